// Hostile inputs: MPI ranks started with different command lines
// (`mpirun -np 1 fiberlab run A.yaml : -np 1 fiberlab run B.yaml`) must agree
// on the resolved config and every flag that changes the output before any
// photon: otherwise exit 2 on every rank, one line (from rank 0) naming the
// differing rank and field, no file written, no hang, no heap corruption.
// Ranks may differ in --threads only, and then the file is the one a single
// process writes (the sums are exact: sim/run/simulation.h).
// Labelled "sanitize" (tests/CMakeLists.txt): the sanitizer job runs these.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "tests/robustness/command_outcome.h"
#include "tests/unique_temp_dir.h"

namespace {

namespace fs = std::filesystem;

using fiberlab::robustness::Outcome;

using fiberlab::robustness::slurp;

constexpr const char* kBase =
    "photons: 3000\nseed: 7\nfiber: {eta: 1.55, sigma_a: [0.1, 0.2]}\n"
    "roughness: {model: gaussian, beta_long: 5}\nsource: {theta_i: [10, 40]}\n"
    "tally: {n_theta: 9, n_phi: 12, lobes: 3}\n";

class HostileRanks : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    shared_ = fiberlab::test_support::unique_temp_dir("fiberlab_ranks");
    mpirun_ = find_mpirun();
    if (mpirun_.empty()) return;
    std::ofstream(shared_ / "base.yaml") << kBase;
    // A build without MPI refuses to be started by mpirun: nothing to test.
    const std::string probe = launcher() + " -np 2 " + FIBERLAB_BINARY + " run " +
                              (shared_ / "base.yaml").string() + " --quiet -o " +
                              (shared_ / "probe.h5").string() + " >" + (shared_ / "probe.err").string() +
                              " 2>&1";
    const int raw = std::system(probe.c_str());
    mpi_works_ = WIFEXITED(raw) && WEXITSTATUS(raw) == 0;
    probe_output_ = slurp(shared_ / "probe.err");
  }
  static void TearDownTestSuite() { fs::remove_all(shared_); }

  void SetUp() override {
    if (mpirun_.empty()) GTEST_SKIP() << "mpirun is not installed (openmpi-bin)";
    if (!mpi_works_) GTEST_SKIP() << "fiberlab does not run under mpirun here: " << probe_output_;
    dir_ = shared_ / ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::create_directories(dir_);
  }

  static std::string find_mpirun() {
    for (const char* p : {"/usr/bin/mpirun", "/usr/local/bin/mpirun"})
      if (access(p, X_OK) == 0) return p;
    return "";
  }
  // Open MPI as root needs --allow-run-as-root; two slots on a small machine --oversubscribe.
  static std::string launcher() {
    return "timeout 300 " + mpirun_ + " --allow-run-as-root --oversubscribe";
  }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  std::string config(const std::string& name, const std::string& text) const {
    std::ofstream(path(name)) << text;
    return path(name);
  }

  // Rank 0 runs `a`, rank 1 runs `b` (each "CONFIG [flags]").
  Outcome two_ranks(const std::string& a, const std::string& b) const {
    const std::string bin = FIBERLAB_BINARY;
    const std::string cmd = launcher() + " -np 1 " + bin + " run " + a + " : -np 1 " + bin + " run " + b +
                            " >" + path("stdout") + " 2>" + path("stderr");
    const int raw = std::system(cmd.c_str());
    return {WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw), slurp(path("stdout")),
            slurp(path("stderr"))};
  }

  std::set<std::string> listing() const {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) {
      const std::string n = e.path().filename().string();
      if (n != "stdout" && n != "stderr") names.insert(n);
    }
    return names;
  }

  // Exit 2 within the timeout (124 would be a hang), fiberlab's one line
  // naming rank 1 and the field, no result, checkpoint or temporary file.
  void expect_refused(const std::string& a, const std::string& b, std::initializer_list<std::string> needles) {
    const auto before = listing();
    const Outcome o = two_ranks(a, b);
    EXPECT_EQ(o.status, 2) << a << " : " << b << "\n" << o.err;
    std::string ours;  // fiberlab's lines (mpirun adds its own notice of the exit status)
    std::istringstream lines(o.err);
    for (std::string line; std::getline(lines, line);)
      if (line.rfind("fiberlab", 0) == 0) ours += line + "\n";
    EXPECT_EQ(std::count(ours.begin(), ours.end(), '\n'), 1) << o.err;
    EXPECT_NE(ours.find("rank 1 was started with another config or flags than rank 0"), std::string::npos)
        << o.err;
    for (const std::string& n : needles) EXPECT_NE(ours.find(n), std::string::npos) << "missing '" << n << "' in " << o.err;
    EXPECT_EQ(o.err.find("AddressSanitizer"), std::string::npos) << o.err;
    EXPECT_EQ(listing(), before) << "files appeared";
    std::cout << "    " << ours;
  }

  static inline fs::path shared_;
  static inline std::string mpirun_, probe_output_;
  static inline bool mpi_works_ = false;
  fs::path dir_;
};

std::string with(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::runtime_error("no '" + from + "' in the base config");
  return text.replace(at, from.size(), to);
}

TEST_F(HostileRanks, DifferentEta) {
  const std::string a = config("a.yaml", kBase), b = config("b.yaml", with(kBase, "eta: 1.55", "eta: 1.6"));
  const std::string out = " --quiet -o " + path("out.h5");
  expect_refused(a + out, b + out, {"fiber.eta = 1.6 on rank 1, 1.55 on rank 0"});
}

TEST_F(HostileRanks, DifferentSigmaA) {
  const std::string a = config("a.yaml", kBase),
                    b = config("b.yaml", with(kBase, "sigma_a: [0.1, 0.2]", "sigma_a: [0.1, 0.3]"));
  const std::string out = " --quiet -o " + path("out.h5");
  expect_refused(a + out, b + out, {"fiber.sigma_a = [0.1, 0.3] on rank 1"});
}

TEST_F(HostileRanks, DifferentSeedFlag) {
  const std::string a = config("a.yaml", kBase);
  const std::string out = " --quiet -o " + path("out.h5");
  expect_refused(a + out + " --seed 3", a + out + " --seed 4", {"seed = 4 on rank 1, 3 on rank 0"});
}

TEST_F(HostileRanks, DifferentPhotons) {
  // Different photon counts would leave one rank waiting in a collective call
  // the other never makes: refused before any tally.
  const std::string a = config("a.yaml", kBase);
  const std::string out = " --quiet -o " + path("out.h5");
  expect_refused(a + out, a + out + " --photons 5000", {"photons = 5000 on rank 1, 3000 on rank 0"});
}

TEST_F(HostileRanks, DifferentTallyShape) {
  // Different n_theta once corrupted the heap in the sum of the tallies (exit 134).
  const std::string a = config("a.yaml", kBase),
                    b = config("b.yaml", with(kBase, "n_theta: 9", "n_theta: 90"));
  const std::string out = " --quiet -o " + path("out.h5");
  expect_refused(a + out, b + out, {"tally.n_theta = 90 on rank 1, 9 on rank 0"});
}

TEST_F(HostileRanks, DifferentTargetErrorAndOutput) {
  const std::string a = config("a.yaml", kBase);
  expect_refused(a + " --quiet -o " + path("out.h5"), a + " --quiet -o " + path("out.h5") + " --target-error 0.5",
                 {"target_error = 0.5 on rank 1, 0 on rank 0"});
  expect_refused(a + " --quiet -o " + path("out.h5"), a + " --quiet -o " + path("other.h5"),
                 {"output = ", "other.h5"});
}

// Only --threads may differ, and the result is then bit for bit the one of a
// single process: every rank takes its share of the same photons (the first
// round's size once depended on each rank's own thread count, so ranks with
// different --threads traced overlapping photons).
TEST_F(HostileRanks, DifferentThreadsGiveTheSingleProcessFile) {
  // Several rounds: a round takes (threads x ranks) chunks of
  // Simulation::kChunk = 4096 photons at first.
  const std::string a = config("a.yaml", kBase) + " --photons 60000";
  const std::string single = std::string(FIBERLAB_BINARY) + " run " + a + " --quiet --threads 1 -o " + path("single.h5");
  ASSERT_EQ(std::system(single.c_str()), 0);
  const Outcome o = two_ranks(a + " --quiet --threads 3 -o " + path("ranks.h5"),
                              a + " --quiet --threads 1 -o " + path("ranks.h5"));
  ASSERT_EQ(o.status, 0) << o.err;
  std::ofstream(path("same.py")) << R"(import sys, h5py, numpy as np
a, b = h5py.File(sys.argv[1], 'r'), h5py.File(sys.argv[2], 'r')
names = []
a.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
assert 'exact/weight_sum_residual' in names, names
for n in names:
    assert np.array_equal(a[n][...], b[n][...], equal_nan=a[n].dtype.kind == 'f'), n
print(len(names), 'datasets identical')
)";
  const std::string cmp = "/usr/bin/python3 " + path("same.py") + " " + path("single.h5") + " " + path("ranks.h5");
  EXPECT_EQ(std::system(cmp.c_str()), 0);
}

}  // namespace
