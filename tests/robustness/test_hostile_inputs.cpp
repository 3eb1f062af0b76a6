// Nothing a file, a flag or a signal can do crashes fiberlab,
// corrupts a result or loses work silently. Every hostile input below is
// crafted in the test (h5py through /usr/bin/python3, or the shell) from a
// good result; each must give exit status 2, one line naming the problem,
// and no output file (nor temporary file).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <cstring>
#include <set>
#include <string>
#include <thread>

#include "tests/robustness/command_outcome.h"

namespace {

namespace fs = std::filesystem;

using fiberlab::robustness::Outcome;

using fiberlab::robustness::slurp;

class Hostile : public ::testing::Test {
 protected:
  // One good result per test binary, and a second with another seed (for merge).
  static void SetUpTestSuite() {
    shared_ = fs::temp_directory_path() / ("fiberlab_hostile_" + std::to_string(getpid()));
    fs::remove_all(shared_);
    fs::create_directories(shared_);
    std::ofstream(shared_ / "good.yaml") << kGood;
    for (const char* seed : {"1", "2"}) {
      const std::string cmd = std::string(FIBERLAB_BINARY) + " run " + (shared_ / "good.yaml").string() +
                              " --quiet --seed " + seed + " -o " +
                              (shared_ / ("good" + std::string(seed) + ".h5")).string();
      ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    }
  }
  static void TearDownTestSuite() { fs::remove_all(shared_); }

  void SetUp() override {
    dir_ = shared_ / ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::create_directories(dir_);
  }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  Outcome run(const std::string& command) const {
    const std::string cmd = command + " >" + path("stdout") + " 2>" + path("stderr");
    const int raw = std::system(cmd.c_str());
    return {WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw), slurp(path("stdout")),
            slurp(path("stderr"))};
  }
  Outcome fiberlab(const std::string& args) const { return run(std::string(FIBERLAB_BINARY) + " " + args); }

  // A copy of the good result altered by a Python statement on `f`
  // (an h5py.File opened r+), with numpy as np. Its attribute digest
  // (common/h5_integrity.h) is removed: these are deliberate edits, judged
  // by the readers' own checks (damage is tested in test_damaged_files.cpp).
  std::string crafted(const std::string& name, const std::string& python) const {
    const std::string file = path(name);
    fs::copy_file(shared_ / "good1.h5", file, fs::copy_options::overwrite_existing);
    std::ofstream(path("craft.py")) << "import h5py, numpy as np, sys\n"
                                    << "f = h5py.File(sys.argv[1], 'r+')\n"
                                    << python << "\nf.attrs.pop('attribute_digest', None)\nf.close()\n";
    const Outcome o = run("/usr/bin/python3 " + path("craft.py") + " " + file);
    EXPECT_EQ(o.status, 0) << o.err;
    return file;
  }

  // exit 2, one line on stderr holding every needle, nothing new but `allowed`.
  void expect_refused(const std::string& args, std::initializer_list<std::string> needles) const {
    const auto before = listing();
    const Outcome o = fiberlab(args);
    EXPECT_EQ(o.status, 2) << args << "\n" << o.err;
    EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << o.err;
    EXPECT_TRUE(o.out.empty() || o.out.find("nan") == std::string::npos) << o.out;
    for (const std::string& n : needles) EXPECT_NE(o.err.find(n), std::string::npos) << "missing '" << n << "' in " << o.err;
    EXPECT_EQ(listing(), before) << "files appeared: " << args;
    std::cout << "    " << o.err;  // what a user sees (quoted in the report)
  }

  // Names in the test folder (not stdout/stderr).
  std::set<std::string> listing() const {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) {
      const std::string n = e.path().filename().string();
      if (n != "stdout" && n != "stderr") names.insert(n);
    }
    return names;
  }

  // Every reader refuses the file: info, merge (nothing written), energy.
  void expect_every_reader_refuses(const std::string& file, std::initializer_list<std::string> needles) const {
    expect_refused("info " + file, needles);
    expect_refused("merge " + file + " " + (shared_ / "good2.h5").string() + " -o " + path("merged.h5"), needles);
    expect_refused("energy " + file + " --models deon2011", needles);
  }

  static constexpr const char* kGood =
      "photons: 2000\nfiber: {sigma_a: [0.1, 0.2]}\nroughness: {model: gaussian, beta_long: 5}\n"
      "source: {theta_i: [10, 40]}\ntally: {n_theta: 9, n_phi: 12, lobes: 3}\n";
  static inline fs::path shared_;
  fs::path dir_;
};

// ------------------------------------------------------------ result files

TEST_F(Hostile, ShortCountDataset) {
  const auto f = crafted("short.h5", "del f['tally/count']; f['tally/count'] = np.ones((2, 3, 9, 11), np.uint64)");
  expect_every_reader_refuses(f, {"short.h5", "/tally/count", "2 x 3 x 9 x 11", "2 x 3 x 9 x 12"});
}

TEST_F(Hostile, ShortLedger) {
  const auto f = crafted("ledger.h5", "del f['ledger/exited']; f['ledger/exited'] = np.ones((2, 3, 1))");
  expect_every_reader_refuses(f, {"/ledger/exited", "K x L x C"});
}

TEST_F(Hostile, EmptySource) {
  const auto f = crafted("empty_phi.h5", "del f['source/phi_i']; f['source/phi_i'] = np.zeros(0)");
  expect_every_reader_refuses(f, {"/source/phi_i", "shape 0"});
}

TEST_F(Hostile, ZeroIncidentDirections) {
  const auto f = crafted("k0.h5",
                         "for n in ['source/theta_i', 'source/phi_i', 'tally/photons']:\n"
                         "    dt = f[n].dtype; del f[n]; f[n] = np.zeros(0, dt)\n"
                         "for n in ['tally/weight_sum', 'tally/weight_sq_sum', 'tally/count', 'ledger/exited', "
                         "'ledger/absorbed', 'ledger/truncated']:\n"
                         "    s = (0,) + f[n].shape[1:]; dt = f[n].dtype; del f[n]; f[n] = np.zeros(s, dt)\n");
  expect_every_reader_refuses(f, {"k0.h5", "/source/theta_i", "shape 0"});
}

TEST_F(Hostile, HugeDeclaredChunkedDataset) {
  // About 8 TB declared, a few KB stored: refused from the shape, before any allocation.
  const auto f = crafted("huge.h5",
                         "del f['tally/weight_sum']\n"
                         "f.create_dataset('tally/weight_sum', shape=(2, 3, 9, 12, 2**33 // 27), dtype='f8', "
                         "chunks=(1, 1, 1, 1, 4096))");
  EXPECT_LT(fs::file_size(f), 1u << 20);
  expect_every_reader_refuses(f, {"/tally/weight_sum", "has shape", "2 x 3 x 9 x 12 x 2"});
}

TEST_F(Hostile, NanNegativeAndInfiniteWeights) {
  expect_every_reader_refuses(crafted("nan.h5", "f['tally/weight_sum'][0, 0, 0, 0, 0] = np.nan"),
                              {"/tally/weight_sum", "nan", "finite and >= 0"});
  expect_refused("info " + crafted("neg.h5", "f['tally/weight_sq_sum'][1, 2, 3, 4, 1] = -1"),
                 {"/tally/weight_sq_sum", "-1", ">= 0"});
  expect_refused("info " + crafted("inf.h5", "f['ledger/absorbed'][0, 1] = np.inf"),
                 {"/ledger/absorbed", "inf"});
}

TEST_F(Hostile, ZeroPhotons) {
  expect_every_reader_refuses(crafted("p0.h5", "f['tally/photons'][1] = 0"), {"/tally/photons[1] = 0", ">= 1"});
}

TEST_F(Hostile, LedgerThatDoesNotBalance) {
  expect_refused("info " + crafted("unbalanced.h5", "f['ledger/absorbed'][0, 0] += 5"),
                 {"/ledger does not balance", "/tally/photons[0]"});
}

TEST_F(Hostile, MoreCountsThanPhotons) {
  expect_refused("info " + crafted("counts.h5", "f['tally/count'][0, 0, 0, 0] = 10**9"),
                 {"/tally/count sums to", "/tally/photons[0]"});
}

TEST_F(Hostile, NanBinEdge) {
  expect_every_reader_refuses(crafted("edge.h5", "f['bins/theta_edges'][3] = np.nan"),
                              {"/bins/theta_edges[3] = nan", "finite"});
}

TEST_F(Hostile, ConfigDisagreesWithBins) {
  const auto f = crafted("mismatch.h5",
                         "f.attrs['config_yaml'] = f.attrs['config_yaml'].replace('n_theta: 9', 'n_theta: 10')");
  expect_every_reader_refuses(f, {"/bins/theta_edges", "has shape 10", "must be 11"});
  const auto g = crafted("edges.h5", "f['bins/phi_edges'][5] += 0.01");
  expect_refused("info " + g, {"/bins/phi_edges[5]", "does not match config_yaml"});
}

TEST_F(Hostile, WrongFormatOrVersion) {
  expect_every_reader_refuses(crafted("v99.h5", "f.attrs['format_version'] = 99"),
                              {"format_version = 99", "reads 1 to 2"});
  expect_refused("info " + crafted("fmt.h5", "f.attrs['format'] = 'fiber-prediction-x'"),
                 {"not a fiberlab result file"});
  expect_refused("info " + crafted("nover.h5", "del f.attrs['format_version']"), {"format_version is missing"});
}

TEST_F(Hostile, EmptyStoredConfig) {
  expect_refused("info " + crafted("noconf.h5", "f.attrs['config_yaml'] = '# nothing\\n'"),
                 {"config_yaml", "empty"});
}

TEST_F(Hostile, NegativeSignedCounts) {
  expect_refused("info " + crafted("signed.h5",
                                   "c = f['tally/count'][:].astype(np.int64); c[0, 0, 0, 0] = -3\n"
                                   "del f['tally/count']; f['tally/count'] = c"),
                 {"/tally/count", "negative count -3"});
}

TEST_F(Hostile, BadMergedSeeds) {
  expect_refused("info " + crafted("seeds.h5", "f.attrs['merged_seeds'] = np.array([1.5])"),
                 {"merged_seeds", "1.5", "integers"});
}

// ------------------------------------------------------------ integers

TEST_F(Hostile, LargestSeedRoundTripsExactly) {
  std::ofstream(path("c.yaml")) << kGood;
  ASSERT_EQ(fiberlab("run " + path("c.yaml") + " --quiet --seed 18446744073709551615 -o " + path("a.h5")).status, 0);
  ASSERT_EQ(fiberlab("run " + path("c.yaml") + " --quiet --seed 18446744073709551614 -o " + path("b.h5")).status, 0);
  // float64 would make these two seeds equal (and merge refuse them as a repeat).
  // merge lists seeds in increasing order; the file's seed is the first.
  const Outcome m = fiberlab("merge " + path("a.h5") + " " + path("b.h5") + " -o " + path("m.h5"));
  ASSERT_EQ(m.status, 0) << m.err;
  std::ofstream(path("check.py"))
      << "import h5py, sys\nf = h5py.File(sys.argv[1])\n"
         "assert f.attrs['seed'] == 2**64 - 2 and f.attrs['seed'].dtype == 'uint64', f.attrs['seed']\n"
         "s = [int(x) for x in f.attrs['merged_seeds']]\n"
         "assert s == [2**64 - 2, 2**64 - 1] and f.attrs['merged_seeds'].dtype == 'uint64', s\n";
  const Outcome c = run("/usr/bin/python3 " + path("check.py") + " " + path("m.h5"));
  EXPECT_EQ(c.status, 0) << c.err;
  EXPECT_NE(fiberlab("info " + path("m.h5")).out.find("18446744073709551614, 18446744073709551615"), std::string::npos);
  // fiberlab 0.1 stored the seed as int64: -1 is read back as 2^64 - 1.
  const auto legacy = crafted("legacy.h5", "f.attrs['seed'] = np.int64(-1); del f.attrs['merged_seeds']");
  EXPECT_NE(fiberlab("info " + legacy).out.find("seeds: 18446744073709551615"), std::string::npos);
}

// Format 2 stores the exact bin sums as residuals against the float64 sums
// (sim/store/exact_tally.h): merge, which adds the exact sums, refuses a residual
// that does not belong to its float64 value.
TEST_F(Hostile, ExactResidualThatDisagreesWithItsFloatSum) {
  const auto f = crafted("residual.h5",
                         "i = tuple(np.argwhere(f['tally/weight_sum'][...] == 0)[0])\n"
                         "f['exact/weight_sum_residual'][i] = 1");
  expect_refused("merge " + f + " " + (shared_ / "good2.h5").string() + " -o " + path("merged.h5"),
                 {"/tally/weight_sum and /exact/weight_sum_residual disagree", "rounded once"});
}

// Format 1 files (fiberlab before format 2: the bin sums as (high, low)
// pairs) still merge, to the same file as their format 2 form. The pairs
// are made here from the format 2 file in Python's exact integers.
TEST_F(Hostile, Format1FilesMergeAsBefore) {
  const auto v1 = crafted("v1.h5",
                          "for n in ('weight_sum', 'weight_sq_sum'):\n"
                          "    v = f['tally/' + n][...]; r = f['exact/' + n + '_residual'][...]\n"
                          "    e = [int(a * 2.0**60) + int(b) for a, b in zip(v.ravel(), r.ravel())]\n"
                          "    p = np.array([[x >> 64, x & (2**64 - 1)] for x in e], np.uint64)\n"
                          "    del f['exact/' + n + '_residual']\n"
                          "    f['exact/' + n] = p.reshape(v.shape + (2,))\n"
                          "f.attrs['format_version'] = 1");
  const std::string good = (shared_ / "good1.h5").string(), other = (shared_ / "good2.h5").string();
  ASSERT_EQ(fiberlab("merge " + v1 + " " + other + " -o " + path("m1.h5")).status, 0);
  ASSERT_EQ(fiberlab("merge " + good + " " + other + " -o " + path("m2.h5")).status, 0);
  std::ofstream(path("same.py"))
      << "import h5py, numpy as np, sys\n"
         "a, b = h5py.File(sys.argv[1]), h5py.File(sys.argv[2])\n"
         "assert a.attrs['format_version'] == 2\n"
         "names = []\n"
         "b.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)\n"
         "assert 'exact/weight_sum_residual' in names and 'tally/weight_sum' in names, names\n"
         "assert any(np.any(b[n][...] != 0) for n in ('exact/weight_sum_residual', 'exact/weight_sq_sum_residual'))\n"
         "for n in names: assert np.array_equal(a[n][...], b[n][...]), n\n";
  const Outcome c = run("/usr/bin/python3 " + path("same.py") + " " + path("m1.h5") + " " + path("m2.h5"));
  EXPECT_EQ(c.status, 0) << c.err;
}

TEST_F(Hostile, IntegerFlags) {
  std::ofstream(path("c.yaml")) << kGood;
  const std::string run = "run " + path("c.yaml") + " --quiet -o " + path("x.h5");
  expect_refused(run + " --photons -1", {"--photons = -1", "out of range"});
  expect_refused(run + " --photons 0", {"--photons = 0"});
  expect_refused(run + " --photons 1.5", {"--photons = 1.5", "not an integer"});
  expect_refused(run + " --photons 18446744073709551616", {"--photons", "out of range"});
  expect_refused(run + " --seed -1", {"--seed = -1"});
  expect_refused(run + " --threads 0", {"--threads = 0", "[1, 1024]"});
  expect_refused(run + " --threads 100000", {"--threads = 100000", "[1, 1024]"});
  expect_refused("run " + path("c.yaml") + " -o ''", {"-o is empty"});
  // photons x 2 incident directions beyond 2^64 - 1: refused, never wrapped.
  expect_refused(run + " --photons 18446744073709551615", {"exceeds 2^64 - 1"});
  // 1e3 is an integer, as in the config.
  const Outcome ok = fiberlab(run + " --photons 1e3");
  ASSERT_EQ(ok.status, 0) << ok.err;
  EXPECT_NE(fiberlab("info " + path("x.h5")).out.find("1000 photons"), std::string::npos);
}

TEST_F(Hostile, LargestPhotonCountRunsInsteadOfWrapping) {
  // 2^64 - 1 photons once wrapped to 0 chunks and "finished" at once. It must
  // run (here: still running after a second), and SIGINT must leave nothing.
  std::ofstream(path("c.yaml")) << "photons: 18446744073709551615\ntally: {n_theta: 9, n_phi: 12}\n";
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    signal(SIGINT, SIG_DFL);  // a background job of a non-interactive shell ignores it
    const std::string out = path("big.h5");
    execl(FIBERLAB_BINARY, "fiberlab", "run", path("c.yaml").c_str(), "--quiet", "--threads", "1", "-o",
          out.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  int status = 0;
  EXPECT_EQ(waitpid(pid, &status, WNOHANG), 0) << "finished at once: the photon count wrapped";
  kill(pid, SIGINT);
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  EXPECT_FALSE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  for (const auto& e : fs::directory_iterator(dir_))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
}

// ------------------------------------------------------------ configs

TEST_F(Hostile, EmptyOrCommentOnlyConfig) {
  std::ofstream(path("zero.yaml")) << "";
  std::ofstream(path("comments.yaml")) << "# photons: 10\n\n   # nothing else\n";
  expect_refused("run " + path("zero.yaml") + " -o " + path("x.h5"), {"zero.yaml", "the config is empty"});
  expect_refused("run " + path("comments.yaml") + " -o " + path("x.h5"), {"comments.yaml", "the config is empty"});
  expect_refused("predict " + path("zero.yaml") + " --model exact -o " + path("x.h5"), {"the config is empty"});
}

TEST_F(Hostile, EndlessConfigStream) {
  expect_refused("run /dev/zero -o " + path("x.h5"), {"/dev/zero", "larger than 16 MiB"});
}

TEST_F(Hostile, EnergyFlags) {
  std::ofstream(path("c.yaml")) << kGood;
  const std::string e = "energy " + path("c.yaml") + " --models deon2011";
  expect_refused(e + " --theta-i 0:1:1e-300", {"--theta-i", "angles (at most 100000)"});
  expect_refused(e + " --theta-i 95,nan", {"--theta-i", "'nan' is not a finite number"});
  expect_refused(e + " --theta-i 95", {"95 is out of range", "(-90, 90)"});
  expect_refused(e + " --beta-sweep 5,-2", {"--beta-sweep", "-2 is out of range"});
  expect_refused(e + " --grid-theta 100000 --grid-phi 100000", {"--grid-theta", "at most"});
}

TEST_F(Hostile, MemoryBudgetFromTheRealFootprint) {
  // 4 lobes x 1000 x 1000 bins x 3 channels passes the file-size rule (0.2 GB)
  // but 1024 per-thread tallies of (2C + 1) int128 per bin need ~460 GB.
  std::ofstream(path("c.yaml")) << "photons: 10\ntally: {n_theta: 1000, n_phi: 1000}\n";
  expect_refused("run " + path("c.yaml") + " --threads 1024 -o " + path("x.h5"),
                 {"the run needs", "GiB", "1024 threads", "available"});
}

TEST_F(Hostile, PredictNeverWritesNonFiniteProbabilities) {
  std::ofstream(path("c.yaml")) << kGood;
  // eta^2 overflows: Appendix B's eta'' = inf / inf in Marschner's pointwise
  // N_TRT, which bin_probabilities() uses where eccentricity makes N_TRT
  // depend on phi (the circular fiber's bins, through the 3D Fresnel, reach
  // the finite perfect-mirror limit instead). Such an eta is refused by the
  // parameter's range (common/physical_limits.h) before any bin is computed;
  // the file's own check (write_finite) stays behind it.
  expect_refused("predict " + path("c.yaml") +
                     " --model marschner2003 --set eta=1e300 --set eccentricity=0.9 -o " + path("p.h5"),
                 {"--set eta=1e300", "(1, 1e9]"});
}

// ------------------------------------------------------------ output targets

TEST_F(Hostile, OutputTargetsThatAreNotRegularFiles) {
  std::ofstream(path("c.yaml")) << kGood;
  const std::string run = "run " + path("c.yaml") + " --quiet -o ";
  ASSERT_EQ(mkfifo(path("fifo").c_str(), 0644), 0);
  expect_refused(run + path("fifo"), {"fifo", "is a FIFO"});
  EXPECT_TRUE(fs::is_fifo(path("fifo")));
  expect_refused(run + "/dev/null", {"/dev/null", "is a character device"});
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  expect_refused(run + dir_.string(), {"is a folder"});
  std::ofstream(path("ro.h5")) << "keep";
  fs::permissions(path("ro.h5"), fs::perms::owner_read | fs::perms::group_read);
  expect_refused(run + path("ro.h5"), {"ro.h5", "read-only"});
  EXPECT_EQ(slurp(path("ro.h5")), "keep");
  expect_refused(run + path("c.yaml"), {"is the input file"});
  EXPECT_EQ(slurp(path("c.yaml")), kGood);
  const std::string good = (shared_ / "good1.h5").string(), other = (shared_ / "good2.h5").string();
  const auto size = fs::file_size(good);
  expect_refused("merge " + good + " " + other + " -o " + good, {"is the input file"});
  EXPECT_EQ(fs::file_size(good), size);
}

TEST_F(Hostile, DiskFullLeavesNothingAndDoesNotCrash) {
  if (geteuid() != 0) GTEST_SKIP() << "mounting a small tmpfs needs root";
  const fs::path small = dir_ / "small";
  fs::create_directories(small);
  std::ofstream(path("c.yaml")) << "photons: 2000\ntally: {n_theta: 90, n_phi: 180}\nsource: {theta_i: [10, 20, 30, 40]}\n";
  // The whole result is ~49 kB: the disk fills in the header's attributes
  // (8k) and in the tallies (24k, 44k); `predict` (~62 kB)
  // writes whole datasets (write_dataset) instead of slabs.
  const std::string out = (small / "r.h5").string();
  for (const auto& [size, command] : std::vector<std::pair<std::string, std::string>>{
           {"8k", "run " + path("c.yaml") + " --quiet -o " + out},
           {"24k", "run " + path("c.yaml") + " --quiet -o " + out},
           {"44k", "run " + path("c.yaml") + " --quiet -o " + out},
           {"40k", "predict " + path("c.yaml") + " --model exact -o " + out}}) {
    if (mount("tmpfs", small.c_str(), "tmpfs", 0, ("size=" + size).c_str()) != 0)
      GTEST_SKIP() << "cannot mount a tmpfs here (" << std::strerror(errno) << ")";
    const Outcome o = fiberlab(command);
    EXPECT_EQ(o.status, 2) << size << " " << command << ": " << o.err;  // not 139 (a crash at exit)
    EXPECT_NE(o.err.find("No space left on device"), std::string::npos) << o.err;
    // The message names the target the user gave, not the temporary file.
    EXPECT_NE(o.err.find(out + ": "), std::string::npos) << o.err;
    EXPECT_EQ(o.err.find(".tmp-"), std::string::npos) << o.err;
    EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << o.err;
    EXPECT_TRUE(fs::is_empty(small)) << "left behind in the full folder";
    umount(small.c_str());
    std::cout << "    " << size << ": " << o.err;
  }
}

}  // namespace
