#pragma once
// A result file (SPEC section 9) written and read one incident direction at
// a time, so that neither `run` nor `merge` ever needs more than one
// direction's tally per file in memory beyond what it holds anyway.
//
// Besides the float64 datasets of SPEC section 9, files carry the exact sums
// (fiberlab's own addition; docs in docs/FILE_FORMAT.md), integers E whose
// value is E / 2^60; the float64 datasets are these values rounded once:
//   /exact/weight_sum_residual, /exact/weight_sq_sum_residual
//       K x L x n_theta x n_phi x C int64: E - (the float64 value) x 2^60
//       (format 2; format 1 stored these sums as the ledger's, below)
//   /exact/exited  K x L x C x 2,  /exact/absorbed, /exact/truncated, /exact/lost  K x C x 2
//       uint64 pairs (high, low) of E.
#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "common/atomic_output.h"
#include "common/h5_file.h"
#include "sim/store/exact_tally.h"
#include "sim/store/result_file.h"
#include "sim/store/tally.h"

namespace fiberlab::sim {

// Which seeds went into each direction: `merge` refuses to add a direction
// twice with the same seed (the same photons). Stored as /merge/direction_seeds
// (M x 2 uint64 rows: direction index, seed) when they are not all the run's seed.
using DirectionSeeds = std::vector<std::vector<std::uint64_t>>;

class ResultWriter {
 public:
  // `header`: a ResultFile of which only the header is written (kept until
  // the file is created; every caller passes one with empty tally arrays,
  // e.g. result_header). The file is created on the first write() or file()
  // (the first write() creates it while its threads deflate); it appears at
  // `path` only on commit().
  ResultWriter(const std::string& path, const ResultFile& header,
               const DirectionSeeds& direction_seeds = {});
  // Each direction once, from exact sums or from a run's tally read in place.
  void write(std::size_t k, const ExactTally& t);
  void write(std::size_t k, const Tally& t);
  h5::File& file();  // for extra groups (checkpoints); creates the file if not yet
  // Threads that convert and deflate the bin datasets' lobes (1 unless set).
  void set_compression_threads(int threads) { threads_ = threads; }
  void commit();  // writes /tally/photons, closes, renames into place

 private:
  // A direction's bins, a lobe and a sum at a time (ExactTally and Tally
  // both give them: lobe_counts, lobe_sums).
  struct BinSource {
    std::function<void(int lobe, std::vector<std::uint64_t>& count)> counts;
    std::function<void(int lobe, BinSum which, std::vector<double>& value,
                       std::vector<std::int64_t>& residual)>
        sums;
  };
  // The BinSource of an ExactTally or a Tally (read in place).
  template <class Tallied>
  static BinSource bins_of(const Tallied& t) {
    return {[&t](int l, std::vector<std::uint64_t>& c) { t.lobe_counts(l, c); },
            [&t](int l, BinSum which, std::vector<double>& v, std::vector<std::int64_t>& r) {
              t.lobe_sums(l, which, v, r);
            }};
  }
  // The bin datasets written a lobe (a row) at a time: S1 and S2 as float64,
  // then their residuals, then the counts.
  using LobePlans = std::array<h5::File::RowPlan, 5>;
  // One writing thread's buffers, kept across lobes and directions: fresh
  // memory costs a page fault per 4 KiB, which on these machines costs more
  // than the conversions. (Its compressor is the thread's, thread_deflater.)
  struct Scratch {
    std::vector<std::uint64_t> count;
    std::vector<double> value;
    std::vector<std::int64_t> residual;
    std::array<h5::File::PreparedRow, 5> unused;  // out of a lobe whose datasets are all slabs_
  };
  // lobe_work[l]: lobe l's relative cost (the lobes are taken heaviest first).
  void write_direction(std::size_t k, const TallyShape& shape, const ExactLedger& ledger,
                       const BinSource& bins, const std::vector<std::size_t>& lobe_work);
  // Part `part` of lobe l (0: S1, 1: S2, 2: the counts) converted and
  // deflated into its rows of out, on one thread with its scratch.
  void prepare_part(int l, int part, const LobePlans& plans, const BinSource& bins, Scratch& s,
                    std::array<h5::File::PreparedRow, 5>& out);
  // The temporary file with the header and every dataset (none written),
  // described (describe_result_file).
  void create_file();
  // The row plan of bin dataset `name` as create_file makes it.
  h5::File::RowPlan planned(const std::string& name) const;

  AtomicOutput out_;
  ResultFile header_;
  DirectionSeeds direction_seeds_;
  std::optional<h5::File> file_;
  std::vector<std::uint64_t> photons_;
  TallyShape shape_;
  std::vector<Scratch> scratch_;   // [thread]
  // [lobe][dataset], until written: rows deflated ahead (direct plans); empty
  // when no plan is direct.
  std::vector<std::array<h5::File::PreparedRow, 5>> prepared_;
  // [dataset]: the other plans' values, the direction's lobes one after the
  // other, written as one slab (a few bytes per lobe, not a PreparedRow of
  // about 600 bytes: a million lobes of 1 x 1 bins took 0.7 GB).
  std::array<h5::File::PreparedRow, 5> slabs_;
  int threads_ = 1;
};

// Writes a whole run (one ExactTally per direction) atomically.
void write_result_exact(const std::string& path, const ResultFile& header,
                        const std::vector<ExactTally>& tallies);

class ResultReader {
 public:
  // Opens and checks a result file: format and version (1 or 2), the stored config,
  // every dataset's shape against K, lobes, bins and channels, photons >= 1,
  // and the presence of the exact sums. Throws fiberlab::Error naming the file.
  // allow_empty_directions: directions of 0 photons (a checkpoint's).
  explicit ResultReader(const std::string& path, bool allow_empty_directions = false);
  const ResultFile& header() const { return header_; }  // no tally arrays
  const DirectionSeeds& direction_seeds() const { return direction_seeds_; }
  TallyShape shape() const { return shape_; }
  ExactTally read(std::size_t k) const;
  const h5::File& file() const { return file_; }

 private:
  void read_bin_sums(std::size_t k, const std::string& name, std::vector<ExactTally::Word>& out) const;
  std::string path_;
  h5::File file_;
  ResultFile header_;
  DirectionSeeds direction_seeds_;
  TallyShape shape_;
  bool has_lost_ = false;  // /exact/lost (absent in files written before it: lost 0)
  bool has_roulette_ = false;  // /exact/roulette (expected-value files only; else 0)
  std::int64_t version_ = 0;  // format_version: 1 (bin sums as pairs) or 2 (as residuals)
};

}  // namespace fiberlab::sim
