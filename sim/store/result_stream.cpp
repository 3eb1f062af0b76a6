#include "sim/store/result_stream.h"

#include <fmt/core.h>

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <exception>
#include <iterator>

#include "common/error.h"
#include "common/file_schema.h"
#include "common/result_layout.h"
#include "sim/store/tally_consistency.h"

namespace fiberlab::sim {

namespace {

enum class Stored {
  Float64,   // float64
  Count,     // uint64
  Pairs,     // uint64, a trailing dimension of 2: (high, low) of a 128-bit sum
  Residual,  // int64: a 128-bit sum minus its float64 dataset's value x 2^60
};

struct DatasetShape {
  const char* name;
  Stored stored;
  int rank;  // 5: K L T P C, 4: K L T P, 3: K L C, 2: K C
};

// Format 2 (kFormatVersion): the bin sums' exact values as residuals.
constexpr DatasetShape kTallyDatasets[] = {
    {"/tally/weight_sum", Stored::Float64, 5},
    {"/tally/weight_sq_sum", Stored::Float64, 5},
    {"/tally/count", Stored::Count, 4},
    {"/ledger/exited", Stored::Float64, 3},
    {"/ledger/absorbed", Stored::Float64, 2},
    {"/ledger/truncated", Stored::Float64, 2},
    {"/exact/weight_sum_residual", Stored::Residual, 5},
    {"/exact/weight_sq_sum_residual", Stored::Residual, 5},
    {"/exact/exited", Stored::Pairs, 3},
    {"/exact/absorbed", Stored::Pairs, 2},
    {"/exact/truncated", Stored::Pairs, 2},
};
// Format 1 stored the bin sums as pairs too (read for merge and resume).
constexpr DatasetShape kFormat1BinSums[] = {{"/exact/weight_sum", Stored::Pairs, 5},
                                            {"/exact/weight_sq_sum", Stored::Pairs, 5}};

// The ledger's `lost` (weight removed by masking). Files written
// before it existed have neither dataset: their lost is 0.
constexpr DatasetShape kLostDatasets[] = {{"/ledger/lost", Stored::Float64, 2},
                                          {"/exact/lost", Stored::Pairs, 2}};
// The ledger's signed `roulette` (Russian roulette): written by the
// expected-value estimator only; a file without it has 0.
constexpr DatasetShape kRouletteDatasets[] = {{"/ledger/roulette", Stored::Float64, 2},
                                              {"/exact/roulette", Stored::Pairs, 2},
                                              {"/tally/lobe_weight_sq_sum", Stored::Float64, 3},
                                              {"/exact/lobe_weight_sq_sum", Stored::Pairs, 3}};

bool plays_roulette(const ResultFile& header) {
  return header.settings.estimator == Estimator::ExpectedValue;
}

h5::Dims dims_of(const DatasetShape& d, hsize_t K, const TallyShape& s) {
  const hsize_t L = s.lobes, T = s.n_theta, P = s.n_phi, C = s.channels;
  h5::Dims dims;
  switch (d.rank) {
    case 5: dims = {K, L, T, P, C}; break;
    case 4: dims = {K, L, T, P}; break;
    case 3: dims = {K, L, C}; break;
    default: dims = {K, C}; break;
  }
  if (d.stored == Stored::Pairs) dims.push_back(2);
  return dims;
}

// The bin datasets a lobe is written to, in LobePlans' order (S1 and S2 as
// float64, their residuals, the counts).
constexpr const char* kLobeRows[] = {"/tally/weight_sum", "/tally/weight_sq_sum",
                                     "/exact/weight_sum_residual",
                                     "/exact/weight_sq_sum_residual", "/tally/count"};

h5::File::Type type_of(const DatasetShape& d) {
  return d.stored == Stored::Float64    ? h5::File::Type::Float64
         : d.stored == Stored::Residual ? h5::File::Type::Int64
                                        : h5::File::Type::UInt64;
}

TallyShape shape_of(const ResultFile& r) {
  return {r.lobes, r.grid.n_theta(), r.grid.n_phi(), r.channels};
}

}  // namespace

ResultWriter::ResultWriter(const std::string& path, const ResultFile& header,
                           const DirectionSeeds& direction_seeds)
    : out_(path), header_(header), direction_seeds_(direction_seeds),
      photons_(header.theta_i.size(), 0), shape_(shape_of(header)) {}

h5::File::RowPlan ResultWriter::planned(const std::string& name) const {
  for (const DatasetShape& d : kTallyDatasets)
    if (name == d.name)
      return h5::File::plan_new_rows(name, dims_of(d, photons_.size(), shape_), type_of(d));
  throw Error("internal error: no dataset " + name);
}

h5::File& ResultWriter::file() {
  if (!file_) create_file();
  return *file_;
}

void ResultWriter::create_file() {
  file_.emplace(h5::File::create(out_.temp_path(), out_.target()));
  h5::File& f = *file_;
  write_result_header(f, header_);
  f.create_group("/tally");
  f.create_group("/ledger");
  f.create_group("/exact");
  const hsize_t K = photons_.size();
  for (const DatasetShape& d : kTallyDatasets)
    f.create_dataset(d.name, dims_of(d, K, shape_), type_of(d));
  for (const DatasetShape& d : kLostDatasets)
    f.create_dataset(d.name, dims_of(d, K, shape_), type_of(d));
  if (plays_roulette(header_))
    for (const DatasetShape& d : kRouletteDatasets)
      f.create_dataset(d.name, dims_of(d, K, shape_), type_of(d));
  if (!direction_seeds_.empty()) {
    std::vector<std::uint64_t> rows;
    for (std::size_t k = 0; k < direction_seeds_.size(); ++k)
      for (std::uint64_t s : direction_seeds_[k]) {
        rows.push_back(k);
        rows.push_back(s);
      }
    f.create_group("/merge");
    f.write("/merge/direction_seeds", {rows.size() / 2, 2}, rows);
  }
  // Attributes only (object headers, no chunk): on this thread, HDF5's, while
  // the others deflate the first direction (write_direction).
  describe_result_file(f, header_);
}

void ResultWriter::write(std::size_t k, const ExactTally& t) {
  // A lobe's cost: its bins that hold anything.
  const std::size_t per_lobe = static_cast<std::size_t>(t.shape.n_theta) * t.shape.n_phi;
  std::vector<std::size_t> work(static_cast<std::size_t>(t.shape.lobes), 0);
  for (std::size_t b = 0; b < t.count.size(); ++b) work[b / per_lobe] += t.count[b] != 0;
  write_direction(k, t.shape, t.ledger(), bins_of(t), work);
}

void ResultWriter::write(std::size_t k, const Tally& t) {
  write_direction(k, t.shape(), t.exact_ledger(), bins_of(t), t.touched_bins_per_lobe());
}

namespace {

// The parts of the lobes to convert and deflate, (lobe, part) with part 0
// S1, 1 S2, 2 the counts: the sums of the heaviest lobes first (ties in lobe
// order), then the counts, the lightest. With the parts handed out to
// threads one at a time, the last ones to start are the lightest, so threads
// finish close together (longest processing time first). On case c (4 M
// photons, 2 threads) the last lobe, p >= 7, is also the densest: as one
// piece of work it keeps one thread busy 13 ms after the other is done.
std::vector<std::pair<int, int>> heaviest_first(const std::vector<std::size_t>& work) {
  std::vector<int> order(work.size());
  for (std::size_t l = 0; l < order.size(); ++l) order[l] = static_cast<int>(l);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return work[a] > work[b]; });
  std::vector<std::pair<int, int>> parts;
  for (int l : order) parts.insert(parts.end(), {{l, 0}, {l, 1}});
  for (int l : order) parts.push_back({l, 2});
  return parts;
}

}  // namespace

// One direction: each lobe's sums converted and its chunks deflated on the
// writer's threads (a lobe is a whole number of chunks of the bin datasets,
// h5::File's chunking), then every chunk handed to HDF5 on this thread (HDF5
// is serial, and its error settings are per thread).
void ResultWriter::write_direction(std::size_t k, const TallyShape& shape,
                                   const ExactLedger& ledger, const BinSource& bins,
                                   const std::vector<std::size_t>& lobe_work) {
  if (!(shape == shape_) || k >= photons_.size() ||
      lobe_work.size() != static_cast<std::size_t>(shape_.lobes))
    throw Error("internal error: writing a tally of the wrong shape or direction");
  photons_[k] = ledger.photons;
  // Before the file exists (its first direction), the plans come from the
  // layout the datasets will have, and the file is created on this thread
  // (HDF5's) while the other threads convert and deflate the first parts.
  const bool create = !file_;
  LobePlans plans;
  static_assert(std::size(kLobeRows) == std::tuple_size_v<LobePlans>);
  for (std::size_t r = 0; r < plans.size(); ++r)
    plans[r] = create ? planned(kLobeRows[r]) : file_->plan_rows(kLobeRows[r]);
  bool any_direct = false;
  for (const h5::File::RowPlan& plan : plans) any_direct = any_direct || plan.direct;
  prepared_.resize(any_direct ? static_cast<std::size_t>(shape_.lobes) : 0);
  // The slabs of the other plans, whole directions: rows 0-3 hold T x P x C
  // cells per lobe, the counts T x P.
  const std::size_t cells = static_cast<std::size_t>(shape_.n_theta) * shape_.n_phi;
  const std::size_t L = static_cast<std::size_t>(shape_.lobes), C = static_cast<std::size_t>(shape_.channels);
  for (std::size_t r = 0; r < plans.size(); ++r) {
    h5::File::PreparedRow& slab = slabs_[r];
    const std::size_t n = plans[r].direct ? 0 : L * cells * (r == 4 ? 1 : C);
    if (r < 2) slab.doubles.resize(n);
    else if (r < 4) slab.signed_words.resize(n);
    else slab.words.resize(n);
  }
  const int threads = std::clamp(threads_, 1, shape_.lobes);
  if (scratch_.size() < static_cast<std::size_t>(threads)) scratch_.resize(threads);
  std::exception_ptr failure;  // the first; the parts after it are skipped
  std::atomic<bool> failed{false};
  const auto record_failure = [&] {
#pragma omp critical(result_writer_failure)
    if (!failure) failure = std::current_exception();
    failed = true;
  };
  const std::vector<std::pair<int, int>> parts = heaviest_first(lobe_work);
#pragma omp parallel num_threads(threads)
  {
    if (create && omp_get_thread_num() == 0) {
      try {
        create_file();
      } catch (...) {
        record_failure();
      }
    }
#pragma omp for schedule(dynamic) nowait
    for (std::size_t i = 0; i < parts.size(); ++i) {
      const auto [l, part] = parts[i];
      if (failed) continue;
      try {
        Scratch& scratch = scratch_[omp_get_thread_num()];
        prepare_part(l, part, plans, bins, scratch, any_direct ? prepared_[l] : scratch.unused);
      } catch (...) {
        record_failure();
      }
    }
  }
  if (failure) std::rethrow_exception(failure);
  h5::File& f = *file_;
  if (create)
    for (h5::File::RowPlan& plan : plans) f.attach(plan);
  for (int l = 0; l < shape_.lobes; ++l)
    for (std::size_t r = 0; r < plans.size(); ++r)
      if (plans[r].direct) f.write_row(plans[r], k, static_cast<hsize_t>(l), prepared_[l][r]);
  for (std::size_t r = 0; r < plans.size(); ++r)
    if (!plans[r].direct) f.write_rows(plans[r], k, slabs_[r]);
  for (const h5::File::RowPlan& plan : plans) f.end_rows(plan);
  f.start_writeback();
  f.write_slab("/ledger/exited", k, ExactTally::to_double(ledger.exited));
  f.write_slab("/ledger/absorbed", k, ExactTally::to_double(ledger.absorbed));
  f.write_slab("/ledger/truncated", k, ExactTally::to_double(ledger.truncated));
  f.write_slab("/ledger/lost", k, ExactTally::to_double(ledger.lost));
  f.write_slab("/exact/exited", k, ExactTally::to_pairs(ledger.exited));
  f.write_slab("/exact/absorbed", k, ExactTally::to_pairs(ledger.absorbed));
  f.write_slab("/exact/truncated", k, ExactTally::to_pairs(ledger.truncated));
  f.write_slab("/exact/lost", k, ExactTally::to_pairs(ledger.lost));
  if (plays_roulette(header_)) {
    f.write_slab("/ledger/roulette", k, ExactTally::to_double_signed(ledger.roulette));
    f.write_slab("/exact/roulette", k, ExactTally::to_pairs(ledger.roulette));
    f.write_slab("/tally/lobe_weight_sq_sum", k, ExactTally::to_double(ledger.lobe_weight_sq_sum));
    f.write_slab("/exact/lobe_weight_sq_sum", k, ExactTally::to_pairs(ledger.lobe_weight_sq_sum));
  }
}

void ResultWriter::prepare_part(int l, int part, const LobePlans& plans, const BinSource& bins,
                                Scratch& s, std::array<h5::File::PreparedRow, 5>& out) {
  const auto deflater = [](const h5::File::RowPlan& plan) -> Deflater& {
    return thread_deflater(plan.direct ? plan.level : 1);  // (unused when not direct)
  };
  // A direct plan's row deflated into out; another's values copied into its
  // place in the direction's slab (lobe l's cells; threads fill disjoint parts).
  const auto put = [&](std::size_t r, const auto& values, auto& slab) {
    if (plans[r].direct) h5::File::prepare_row(plans[r], values, deflater(plans[r]), out[r]);
    else std::copy(values.begin(), values.end(), slab.begin() + static_cast<std::ptrdiff_t>(l * values.size()));
  };
  if (part == 2) {
    bins.counts(l, s.count);
    put(4, s.count, slabs_[4].words);
    return;
  }
  // S1: rows 0 (values) and 2 (residuals); S2: rows 1 and 3.
  bins.sums(l, part == 0 ? BinSum::S1 : BinSum::S2, s.value, s.residual);
  put(part, s.value, slabs_[part].doubles);
  put(2 + part, s.residual, slabs_[2 + part].signed_words);
}

void ResultWriter::commit() {
  file().write("/tally/photons", {photons_.size()}, photons_);
  describe_tally_photons(*file_);
  file_->close();
  file_.reset();
  out_.commit();
}

void write_result_exact(const std::string& path, const ResultFile& header,
                        const std::vector<ExactTally>& tallies) {
  ResultWriter w(path, header);
  for (std::size_t k = 0; k < tallies.size(); ++k) w.write(k, tallies[k]);
  w.commit();
}

ResultReader::ResultReader(const std::string& path, bool allow_empty_directions)
    : path_(path), file_(h5::File::open_read(path)) {
  const h5::File& f = file_;
  if (!f.has_attr("/", "format") || f.attr_string("/", "format") != "fiber-histogram")
    throw Error(fmt::format("{}: not a fiberlab result file (root attribute format is not "
                            "\"fiber-histogram\")", path));
  version_ = read_format_version(f, path);
  ResultFile& h = header_;
  h.config_yaml = f.attr_string("/", "config_yaml");
  h.settings = parse_stored_settings_yaml(h.config_yaml, path + ":/config_yaml");
  h.software_version = f.attr_string("/", "software_version");
  h.created_utc = f.attr_string("/", "created_utc");
  if (f.has_attr("/", "merged_seeds")) {
    h.seeds = f.attr_uint64s("/", "merged_seeds", 1u << 20);
  } else {
    h.seeds = {f.attr_uint64("/", "seed")};
  }
  if (h.seeds.empty()) throw Error(path + ": merged_seeds is empty");
  h.grid = read_bins(f);
  h.theta_i = f.read_doubles("/source/theta_i");
  h.phi_i = f.read_doubles("/source/phi_i");
  h.photons = f.read_uint64s("/tally/photons");
  h.lobes = h.settings.tally_lobes();
  h.channels = static_cast<int>(h.settings.fiber.sigma_a.size());
  shape_ = shape_of(h);
  const std::size_t K = h.photons.size();
  if (K == 0 || h.theta_i.size() != K || h.phi_i.size() != K)
    throw Error(fmt::format("{}: /tally/photons, /source/theta_i and /source/phi_i must have the "
                            "same length >= 1", path));
  if (h.grid.n_theta() != h.settings.tally.n_theta || h.grid.n_phi() != h.settings.tally.n_phi)
    throw Error(fmt::format("{}: /bins do not match config_yaml's tally", path));
  for (std::uint64_t n : h.photons)
    if (n == 0 && !allow_empty_directions) throw Error(fmt::format("{}: /tally/photons holds 0 (must be >= 1)", path));
  if (!f.exists("/exact"))
    throw Error(fmt::format("{}: has no exact sums (/exact; files written before fiberlab 0.2 "
                            "cannot be merged exactly)", path));
  auto check_shape = [&](const DatasetShape& d) {
    if (f.dims(d.name) != dims_of(d, K, shape_))
      throw Error(fmt::format("{}: {} does not have the shape the config and /source give", path,
                              d.name));
  };
  for (const DatasetShape& d : kTallyDatasets)
    if (version_ >= 2 || d.stored != Stored::Residual) check_shape(d);
  if (version_ == 1)
    for (const DatasetShape& d : kFormat1BinSums) check_shape(d);
  has_lost_ = f.exists(kLostDatasets[1].name);
  for (const DatasetShape& d : kLostDatasets)
    if (has_lost_ && f.dims(d.name) != dims_of(d, K, shape_))
      throw Error(fmt::format("{}: {} does not have the shape the config and /source give", path,
                              d.name));
  has_roulette_ = f.exists(kRouletteDatasets[1].name);
  for (const DatasetShape& d : kRouletteDatasets)
    if (has_roulette_ && f.dims(d.name) != dims_of(d, K, shape_))
      throw Error(fmt::format("{}: {} does not have the shape the config and /source give", path,
                              d.name));
  direction_seeds_.assign(K, h.seeds);
  if (f.exists("/merge/direction_seeds")) {
    h5::Dims dims;
    const std::vector<std::uint64_t> rows = f.read_uint64s("/merge/direction_seeds", &dims);
    if (dims.size() != 2 || dims[1] != 2)
      throw Error(path + ": /merge/direction_seeds is not an M x 2 array");
    for (auto& s : direction_seeds_) s.clear();
    for (std::size_t i = 0; i < rows.size(); i += 2) {
      if (rows[i] >= K) throw Error(path + ": /merge/direction_seeds names a direction >= K");
      direction_seeds_[rows[i]].push_back(rows[i + 1]);
    }
  }
}

ExactTally ResultReader::read(std::size_t k) const {
  ExactTally t(shape_);
  t.photons = header_.photons.at(k);
  t.count = file_.read_slab_uint64s("/tally/count", k);
  if (version_ == 1) {
    t.weight_sum = ExactTally::from_pairs(file_.read_slab_uint64s("/exact/weight_sum", k));
    t.weight_sq_sum = ExactTally::from_pairs(file_.read_slab_uint64s("/exact/weight_sq_sum", k));
  } else {
    read_bin_sums(k, "weight_sum", t.weight_sum);
    read_bin_sums(k, "weight_sq_sum", t.weight_sq_sum);
  }
  t.exited = ExactTally::from_pairs(file_.read_slab_uint64s("/exact/exited", k));
  t.absorbed = ExactTally::from_pairs(file_.read_slab_uint64s("/exact/absorbed", k));
  t.truncated = ExactTally::from_pairs(file_.read_slab_uint64s("/exact/truncated", k));
  if (has_lost_) t.lost = ExactTally::from_pairs(file_.read_slab_uint64s("/exact/lost", k));
  if (has_roulette_) {
    t.roulette = ExactTally::from_pairs(file_.read_slab_uint64s("/exact/roulette", k));
    t.lobe_weight_sq_sum =
        ExactTally::from_pairs(file_.read_slab_uint64s("/exact/lobe_weight_sq_sum", k));
  }
  // Sums that break a tally's identities were damaged or edited: never added.
  if (const std::string why = tally_inconsistency(t, header_.settings.estimator == Estimator::Analog);
      !why.empty())
    throw Error(fmt::format("{}: incident direction {}: {}", path_, k, why));
  return t;
}

// Format 2: a direction's bin sums from /tally/<name> and
// /exact/<name>_residual, refused unless every cell is one that
// ExactTally::split writes (a file altered by hand, or damaged, otherwise
// gives sums that merge would add as if exact).
void ResultReader::read_bin_sums(std::size_t k, const std::string& name,
                                 std::vector<ExactTally::Word>& out) const {
  const std::string value_name = "/tally/" + name, residual_name = "/exact/" + name + "_residual";
  const std::vector<double> value = file_.read_slab_doubles(value_name, k);
  const std::vector<std::int64_t> residual = file_.read_slab_int64s(residual_name, k);
  const std::ptrdiff_t bad = ExactTally::join(value, residual, out);
  if (bad >= 0)
    throw Error(fmt::format("{}: {} and {} disagree in direction {}, cell {} ({} and {}): the "
                            "float64 sum must be the exact sum / 2^60 rounded once",
                            path_, value_name, residual_name, k, bad, value[bad], residual[bad]));
}

}  // namespace fiberlab::sim
