// The ledger's `lost` through the files: the exact sums a run
// writes (as `fiberlab run` and checkpoints do), the validating reader's
// balance exited + absorbed + truncated + lost = N, files written before
// `lost` existed (read as 0), a tampered `lost` (refused), and the exact sums'
// flat words (MPI, merge) carrying it.
//
// Seen before the fix (not a planted mutation): Tally::score_lost without its
// cap at 1 - kept let the white masking run's exact absorbed wrap below 0, and
// the reader refused the file `fiberlab run` had written. The run's rounding
// does not reproduce that reliably (the cap removed, the round trip passed
// with this seed), so RoundingNeverMakesAbsorbedNegative plants the rounding.
//
// Mutations run (tests/sim/test_microfacet_*.cpp built alone):
// - lost not booked (photon_life's losses.add removed) or not scored
//   (ExitScorer without score_lost): lost[0] > 0.1 fails (0 booked);
// - lost not absorbed along the path: lost[0] > lost[1] fails (equal);
// - ggx <-> beckmann model swap: lost[0] > 0.1 fails (beckmann 0.3 loses 0.07);
// - score_lost's cap removed: RoundingNeverMakesAbsorbedNegative (absorbed
//   wraps round to 2^128 - 256 units); its allowance check removed:
//   DoubleBookingIsAnInternalError.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "common/error.h"
#include "sim/store/checkpoint.h"
#include "sim/store/result_stream.h"
#include "sim/store/tally.h"
#include "tests/sim/sim_test_support.h"

namespace fiberlab::sim {
namespace {

namespace fs = std::filesystem;

class LedgerFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("fiberlab_lost_" + std::to_string(getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Runs s and writes its exact sums as `fiberlab run` does.
  std::string write_run(const Settings& s, const std::string& name) const {
    const Simulation sim(s);
    const std::vector<Tally> tallies = sim.run(2);
    std::vector<ExactTally> exact;
    for (const Tally& t : tallies) exact.push_back(t.exact());
    const std::string path = (dir_ / name).string();
    write_result_exact(path, result_header(s, sim.grid()), exact);
    return path;
  }

  // h5py edits of a file (Debian's python3-h5py).
  void edit(const std::string& path, const std::string& python) const {
    const std::string script = (dir_ / "edit.py").string();
    std::ofstream(script) << "import h5py, sys\nf = h5py.File(sys.argv[1], 'r+')\n" << python << "\nf.close()\n";
    ASSERT_EQ(std::system(("/usr/bin/python3 " + script + " " + path).c_str()), 0);
  }

  fs::path dir_;
};

Settings masked_white_fiber(Masking masking) {
  Settings s = testing::smooth_circle(30.0, 50000);
  s.fiber.scale_tilt = deg_to_rad(3.0);
  s.fiber.sigma_a = {0.0, 0.7};
  s.tally.n_theta = 18;
  s.tally.n_phi = 36;
  s.fiber.roughness = testing::microfacet(MicrofacetModel::GGX, 0.3, 0.3, masking);
  return s;
}

TEST_F(LedgerFile, WhiteMaskingRunWritesAndReadsBack) {
  const std::string path = write_run(masked_white_fiber(Masking::SmithG1), "masked.h5");
  const ResultFile r = read_result(path);  // validates the balance with lost
  const double N = static_cast<double>(r.photons[0]);
  ASSERT_EQ(r.lost.size(), 2u);
  EXPECT_GT(r.lost[0] / N, 0.1);  // GGX 0.3 loses about a quarter
  EXPECT_GT(r.lost[0], r.lost[1]);
  EXPECT_GE(r.absorbed[0], 0.0);
  EXPECT_LT(r.absorbed[0] / N, 1e-12);  // white channel: nothing absorbed, to rounding
  // The exact sums hold the same lost.
  const ResultReader exact(path);
  EXPECT_EQ(ExactTally::to_double(exact.read(0).lost), std::vector<double>(r.lost.begin(), r.lost.end()));
}

TEST_F(LedgerFile, FilesWithoutLostReadAsLosingNothing) {
  const std::string path = write_run(masked_white_fiber(Masking::None), "old.h5");
  edit(path, "del f['ledger/lost']; del f['exact/lost']; f.attrs.pop('attribute_digest', None)");  // as written before the digest and lost existed
  const ResultFile r = read_result(path);
  EXPECT_EQ(r.lost, std::vector<double>(2, 0.0));
  const ResultReader exact(path);
  const ExactTally t = exact.read(0);
  EXPECT_EQ(t.lost, std::vector<ExactTally::Word>(2, 0));
}

TEST_F(LedgerFile, TamperedLostIsRefused) {
  const std::string path = write_run(masked_white_fiber(Masking::SmithG1), "tampered.h5");
  edit(path, "f['ledger/lost'][0, 0] += 1.0");
  try {
    read_result(path);
    FAIL() << "read_result accepted a ledger that does not balance";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("exited + absorbed + truncated + lost"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
}

// A white photon that kept `kept` and lost 1 - kept, the two rounded up by
// 2^-52 as the products of masking factors can be: the exact absorbed is 0,
// not a negative number wrapped round, and the ledger still sums to 1.
TEST(TallyLost, RoundingNeverMakesAbsorbedNegative) {
  for (double kept : {0.0, 0.3, 0.7431}) {
    Tally t(1, 1, 1, 1);
    const double lost = (1.0 - kept) + 0x1.0p-52;
    if (kept > 0.0) t.score_exit(0, 0, 0, &kept);
    t.score_lost(&lost, &kept);
    t.add_launched(1);
    const ExactTally e = t.exact();
    const ExactTally::Word one = ExactTally::Word{1} << 60;
    EXPECT_EQ(e.absorbed[0], 0u) << "kept " << kept;
    EXPECT_EQ(e.exited[0] + e.lost[0] + e.absorbed[0], one) << "kept " << kept;
  }
}

// More than rounding is a booking error, reported, never clamped (a lost
// factor booked but also left in the weight double-counts the whole factor).
// Mutation caught: the allowance check removed (the excess is clamped
// silently and nothing is thrown).
TEST(TallyLost, DoubleBookingIsAnInternalError) {
  Tally t(1, 1, 1, 1);
  const double kept = 0.6, lost = 0.5;
  t.score_exit(0, 0, 0, &kept);
  EXPECT_THROW(t.score_lost(&lost, &kept), Error);
}

TEST(ExactTallyLost, WordsAndSumsCarryLost) {
  ExactTally a(TallyShape{2, 3, 4, 2});
  a.lost = {5, 7};
  a.photons = 1;
  ExactTally b = a;
  b += a;
  EXPECT_EQ(b.lost, (std::vector<ExactTally::Word>{10, 14}));
  ExactTally c(a.shape);
  c.from_words(b.words());
  EXPECT_EQ(c.lost, b.lost);
}

}  // namespace
}  // namespace fiberlab::sim
