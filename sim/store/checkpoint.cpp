#include "sim/store/checkpoint.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <string_view>

#include "common/error.h"
#include "common/file_schema.h"
#include "common/h5_integrity.h"
#include "common/result_layout.h"
#include "common/units.h"
#include "sim/store/result_stream.h"

namespace fiberlab::sim {

std::string checkpoint_path(const std::string& output) {
  const std::string ext = ".h5";
  if (output.size() > ext.size() && output.ends_with(ext))
    return output.substr(0, output.size() - ext.size()) + ".checkpoint.h5";
  return output + ".checkpoint.h5";
}

namespace {

// FNV-1a (64 bits) of the resolved config's text (to_yaml), stored as
// /checkpoint@config_digest: a stored config_yaml that was changed, or that
// does not resolve to itself, is refused.
std::uint64_t config_digest(std::string_view text) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char ch : text) h = (h ^ ch) * 0x100000001b3ULL;
  return h;
}

// FNV-1a (64 bits) continued over a direction's exact words (ExactTally::words:
// photons, counts, bin sums, ledger), each as 16 little-endian bytes: stored
// as /checkpoint@sums_digest over every direction in order, so that a sum
// edited within the tally's identities (a count moved between bins) is refused.
// The ledger's roulette and the lobes' photon S2 (the last C + L C words)
// count only where they are not all 0, so that checkpoints of the analog
// estimator keep the digest they had before those sums existed.
std::uint64_t add_sums(std::uint64_t h, const ExactTally& t) {
  std::vector<ExactTally::Word> words = t.words();
  words.resize(words.size() - t.roulette.size() - t.lobe_weight_sq_sum.size());
  const auto zero = [](ExactTally::Word w) { return w == 0; };
  if (!std::all_of(t.roulette.begin(), t.roulette.end(), zero))
    words.insert(words.end(), t.roulette.begin(), t.roulette.end());
  if (t.has_lobe_weight_sq_sum())
    words.insert(words.end(), t.lobe_weight_sq_sum.begin(), t.lobe_weight_sq_sum.end());
  for (const ExactTally::Word w : words)
    for (int b = 0; b < 16; ++b) h = (h ^ static_cast<unsigned char>(w >> (8 * b))) * 0x100000001b3ULL;
  return h;
}
constexpr std::uint64_t kFnvBasis = 0xcbf29ce484222325ULL;

[[noreturn]] void inconsistent(const std::string& path, const std::string& what) {
  throw Error(fmt::format("{}: inconsistent checkpoint: {} (it was damaged or edited; delete it "
                          "and run again)", path, what));
}

// /fiber and /roughness hold the stored config's values (sim/store/result_file.cpp
// writes both from the same Settings), exactly.
void check_parameter_groups(const h5::File& f, const Settings& s, const std::string& path) {
  const auto same = [&](const char* group, const char* name, const std::vector<double>& expected) {
    const std::string obj = std::string("/") + group;
    if (!f.has_attr(obj, name)) inconsistent(path, fmt::format("{}@{} is missing", obj, name));
    if (f.attr_doubles(obj, name) != expected)
      inconsistent(path, fmt::format("{}@{} does not match the stored config_yaml's {}.{}", obj,
                                     name, group, name));
  };
  same("fiber", "eta", {s.fiber.eta});
  same("fiber", "eccentricity", {s.fiber.eccentricity});
  same("fiber", "scale_tilt", {s.fiber.scale_tilt});
  same("fiber", "sigma_a", s.fiber.sigma_a);
  for (const roughness::Attribute& a : roughness::attributes(s.fiber.roughness))
    if (const auto* numbers = std::get_if<std::vector<double>>(&a.value))
      same("roughness", a.name.c_str(), *numbers);
  if (f.attr_string("/roughness", "model") != roughness::name(s.fiber.roughness))
    inconsistent(path, "/roughness@model does not match the stored config_yaml's roughness.model");
}

}  // namespace

ResultFile result_header(const Settings& settings, const BinGrid& grid) {
  return make_result(settings, grid, {});
}

void write_checkpoint(const std::string& path, const Simulation& sim, const RunProgress& state,
                      double target_error) {
  ResultWriter w(path, result_header(sim.settings(), sim.grid()));
  std::uint64_t sums = kFnvBasis;
  for (std::size_t k = 0; k < state.tallies.size(); ++k) {
    const ExactTally t = state.tallies[k].exact();
    sums = add_sums(sums, t);
    w.write(k, t);
  }
  h5::File& f = w.file();
  f.set_attr("/", "target_error", target_error);
  f.create_group("/checkpoint");
  f.set_attr("/checkpoint", "checkpoint_version", static_cast<std::int64_t>(kCheckpointVersion));
  f.set_attr("/checkpoint", "chunk", static_cast<std::int64_t>(Simulation::kChunk));
  f.set_attr("/checkpoint", "target_batch", static_cast<std::int64_t>(Simulation::kTargetBatch));
  f.set_attr("/checkpoint", "config_digest", config_digest(to_yaml(sim.settings())));
  f.set_attr("/checkpoint", "sums_digest", sums);
  f.write("/checkpoint/next_photon", {state.next_photon.size()}, state.next_photon);
  std::vector<std::uint64_t> done(state.done.begin(), state.done.end());
  f.write("/checkpoint/done", {done.size()}, done);
  describe(f, "/checkpoint/next_photon", "incidence", "photons",
           "photons [0, next_photon) of each incident direction are in the sums");
  describe(f, "/checkpoint/done", "incidence", "0/1", "1 once the incident direction is finished");
  w.commit();
}

Checkpoint read_checkpoint(const std::string& path, bool with_tallies) {
  const ResultReader reader(path, /*allow_empty_directions=*/true);
  const h5::File& f = reader.file();
  if (!f.exists("/checkpoint"))
    throw Error(fmt::format("{}: not a fiberlab checkpoint (no /checkpoint group)", path));
  auto attr = [&](const char* name) -> std::int64_t {
    if (!f.has_attr("/checkpoint", name))
      throw Error(fmt::format("{}: /checkpoint@{} is missing", path, name));
    return f.attr_int("/checkpoint", name);
  };
  const std::string version = reader.header().software_version;
  if (version != FIBERLAB_VERSION || attr("checkpoint_version") != kCheckpointVersion)
    throw Error(fmt::format("{}: written by fiberlab {} (checkpoint format {}); this is fiberlab {} "
                            "(format {}): resume it with the version that wrote it",
                            path, version, attr("checkpoint_version"), FIBERLAB_VERSION,
                            kCheckpointVersion));
  if (attr("chunk") != static_cast<std::int64_t>(Simulation::kChunk) ||
      attr("target_batch") != static_cast<std::int64_t>(Simulation::kTargetBatch))
    throw Error(fmt::format("{}: written with another photon chunking: resume it with the "
                            "fiberlab build that wrote it", path));
  // The config as resolved when written (its digest), then the parameter
  // groups, the progress and the sums against it; last, the attribute digest
  // (checked by h5::File::open_read when present) must be there.
  if (!f.has_attr("/checkpoint", "config_digest"))
    inconsistent(path, "/checkpoint@config_digest is missing");
  Checkpoint c;
  c.settings = reader.header().settings;
  if (f.attr_uint64("/checkpoint", "config_digest") != config_digest(reader.header().config_yaml) ||
      to_yaml(c.settings) != reader.header().config_yaml)
    inconsistent(path, "config_yaml does not match /checkpoint@config_digest");
  check_parameter_groups(f, c.settings, path);
  c.target_error = f.attr_double("/", "target_error");
  if (!(std::isfinite(c.target_error) && c.target_error >= 0.0))
    inconsistent(path, fmt::format("target_error = {} (must be finite and >= 0)", c.target_error));
  const std::size_t K = c.settings.incidences().size();
  c.state.next_photon = f.read_uint64s("/checkpoint/next_photon");
  const std::vector<std::uint64_t> done = f.read_uint64s("/checkpoint/done");
  if (c.state.next_photon.size() != K || done.size() != K || reader.header().photons.size() != K)
    throw Error(fmt::format("{}: /checkpoint does not have one entry per incident direction", path));
  for (std::size_t k = 0; k < K; ++k) {
    const std::uint64_t next = c.state.next_photon[k];
    // A direction is finished when all its photons are traced, or (with a
    // target error) at a judged batch boundary (Simulation::run).
    const bool early = next < c.settings.photons;
    if (done[k] > 1 || next > c.settings.photons || reader.header().photons[k] != next ||
        (!done[k] && (next % Simulation::kChunk != 0 || next == c.settings.photons)) ||
        (done[k] && early &&
         (next == 0 || c.target_error == 0.0 || next % Simulation::kTargetBatch != 0)))
      inconsistent(path, fmt::format("/checkpoint of direction {} (next_photon {}, done {}) "
                                     "disagrees with /tally/photons[{}] = {} or the config's "
                                     "photons {} (target_error {})",
                                     k, next, done[k], k, reader.header().photons[k],
                                     c.settings.photons, c.target_error));
    c.state.done.push_back(static_cast<std::uint8_t>(done[k]));
  }
  if (with_tallies) {
    // reader.read checks each direction's identities (sim/store/tally_consistency.h).
    const TallyShape s = reader.shape();
    std::uint64_t sums = kFnvBasis;
    for (std::size_t k = 0; k < K; ++k) {
      const ExactTally t = reader.read(k);
      sums = add_sums(sums, t);
      c.state.tallies.emplace_back(s.lobes, s.n_theta, s.n_phi, s.channels);
      c.state.tallies.back().add(t);
    }
    if (!f.has_attr("/checkpoint", "sums_digest") || f.attr_uint64("/checkpoint", "sums_digest") != sums)
      inconsistent(path, "its sums (/tally, /exact) do not match /checkpoint@sums_digest");
  }
  if (!f.has_attr("/", h5::kDigestAttribute))
    inconsistent(path, fmt::format("root attribute {} is missing", h5::kDigestAttribute));
  return c;
}

std::string describe_checkpoint(const std::string& path) {
  const Checkpoint c = read_checkpoint(path, /*with_tallies=*/false);
  const ResultReader reader(path, /*allow_empty_directions=*/true);
  std::string s = fmt::format("{}: fiberlab run checkpoint of {} (software {}, created {}), seed {}\n", path,
                              c.settings.output, reader.header().software_version, reader.header().created_utc,
                              c.settings.seed);
  const std::vector<Settings::Incidence> inc = c.settings.incidences();
  for (std::size_t k = 0; k < inc.size(); ++k) {
    const std::string phi =
        std::isnan(inc[k].phi_i) ? std::string("uniform") : fmt::format("{:g} deg", rad_to_deg(inc[k].phi_i));
    s += fmt::format("theta_i {:g} deg, phi_i {}: {} of {} photons{}\n", rad_to_deg(inc[k].theta_i), phi,
                     c.state.next_photon[k], c.settings.photons, c.state.done[k] ? ", finished" : "");
  }
  return s + fmt::format("resume with: fiberlab run --resume {}\n", path);
}

void check_same_config(const Checkpoint& checkpoint, const Settings& given,
                       const std::string& checkpoint_file) {
  if (to_yaml(given) != to_yaml(checkpoint.settings))
    throw Error(fmt::format("{}: the config given differs from the one the checkpoint was "
                            "started with (resume with `fiberlab run --resume {}` alone)",
                            checkpoint_file, checkpoint_file));
}

}  // namespace fiberlab::sim
