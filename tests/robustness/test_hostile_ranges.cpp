// Hostile inputs: silent wrong physics and verdicts, and late or
// wrong refusals. Each hostile input gives exit status 2, one line naming the
// field, flag or file and what is allowed, and no file; each legitimate
// input at the edge of its range gives the right answer.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
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

constexpr const char* kGood =
    "photons: 2000\nfiber: {sigma_a: [0.1, 0.2]}\nroughness: {model: gaussian, beta_long: 5}\n"
    "source: {theta_i: [10, 40]}\ntally: {n_theta: 9, n_phi: 12, lobes: 3}\n";

class HostileRanges : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    shared_ = fiberlab::test_support::unique_temp_dir("fiberlab_ranges");
    std::ofstream(shared_ / "good.yaml") << kGood;
    const std::string bin = FIBERLAB_BINARY;
    for (const std::string& cmd :
         {bin + " run " + (shared_ / "good.yaml").string() + " --quiet -o " + (shared_ / "good.h5").string(),
          bin + " run " + (shared_ / "good.yaml").string() + " --quiet --seed 2 -o " +
              (shared_ / "good2.h5").string(),
          bin + " predict " + (shared_ / "good.h5").string() + " --model exact -o " +
              (shared_ / "pred.h5").string()})
      ASSERT_EQ(std::system((cmd + " >/dev/null").c_str()), 0) << cmd;
  }
  static void TearDownTestSuite() { fs::remove_all(shared_); }

  void SetUp() override {
    dir_ = shared_ / ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::create_directories(dir_);
  }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  static std::string shared(const std::string& name) { return (shared_ / name).string(); }

  std::string config(const std::string& name, const std::string& text) const {
    std::ofstream(path(name)) << text;
    return path(name);
  }

  Outcome run(const std::string& command) const {
    const std::string cmd = command + " >" + path("stdout") + " 2>" + path("stderr");
    const int raw = std::system(cmd.c_str());
    return {WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw), slurp(path("stdout")),
            slurp(path("stderr"))};
  }
  Outcome fiberlab(const std::string& args) const { return run(std::string(FIBERLAB_BINARY) + " " + args); }

  std::set<std::string> listing() const {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) {
      const std::string n = e.path().filename().string();
      if (n != "stdout" && n != "stderr" && n.find(".yaml") == std::string::npos) names.insert(n);
    }
    return names;
  }

  // exit 2, one line on stderr holding every needle, no new file.
  void expect_refused(const std::string& args, std::initializer_list<std::string> needles) const {
    const auto before = listing();
    const Outcome o = fiberlab(args);
    EXPECT_EQ(o.status, 2) << args << "\n" << o.out << o.err;
    EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << o.err;
    for (const std::string& n : needles)
      EXPECT_NE(o.err.find(n), std::string::npos) << "missing '" << n << "' in " << o.err;
    EXPECT_EQ(listing(), before) << "files appeared: " << args;
    std::cout << "    " << o.err;
  }

  // A Python (h5py, numpy) expression's printed value for file `h5`.
  double python_value(const std::string& h5, const std::string& expression) const {
    std::ofstream(path("value.py")) << "import sys, h5py, numpy as np\nf = h5py.File(sys.argv[1], 'r')\n"
                                    << "print(repr(float(" << expression << ")))\n";
    const Outcome o = run("/usr/bin/python3 " + path("value.py") + " " + h5);
    EXPECT_EQ(o.status, 0) << o.err;
    return o.out.empty() ? NAN : std::stod(o.out);
  }

  // A copy of the prediction file altered by a Python statement on `f`, as
  // another writer would make it (without fiberlab's attribute_digest).
  std::string crafted_prediction(const std::string& name, const std::string& python) const {
    fs::copy_file(shared("pred.h5"), path(name));
    std::ofstream(path("craft.py")) << "import h5py, numpy as np, sys\nf = h5py.File(sys.argv[1], 'r+')\n"
                                    << python << "\nf.attrs.pop('attribute_digest', None)\nf.close()\n";
    const Outcome o = run("/usr/bin/python3 " + path("craft.py") + " " + path(name));
    EXPECT_EQ(o.status, 0) << o.err;
    return path(name);
  }

  static inline fs::path shared_;
  fs::path dir_;
};

// AddressSanitizer reserves terabytes of address space for its shadow
// memory: a process under `ulimit -v` cannot start (the sanitizer job runs
// the rest of this file).
#if defined(__SANITIZE_ADDRESS__)
#define SKIP_UNDER_ADDRESS_LIMIT() GTEST_SKIP() << "ulimit -v and AddressSanitizer do not mix"
#else
#define SKIP_UNDER_ADDRESS_LIMIT() (void)0
#endif

std::string with(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::runtime_error("no '" + from + "' in the config");
  return text.replace(at, from.size(), to);
}

// ------------------------------------------------------------ physics ranges
// The bounds and their derivation: common/physical_limits.h; the numerics at
// and beyond them: tests/sim/test_physical_limits.cpp.

TEST_F(HostileRanges, EtaBeyondWherePhysicsIsComputed) {
  for (const char* eta : {"1e80", "1e308", "1.0000001e9", "inf"}) {
    const std::string c = config("eta.yaml", with(kGood, "fiber: {", std::string("fiber: {eta: ") + eta + ", "));
    expect_refused("run " + c + " -o " + path("out.h5"), {"fiber.eta", "(1, 1e9]"});
    expect_refused("predict " + c + " --model exact -o " + path("p.h5"), {"fiber.eta", "(1, 1e9]"});
  }
  expect_refused("predict " + shared("good.h5") + " --model exact --set eta=1e80 -o " + path("p.h5"),
                 {"--set eta=1e80", "(1, 1e9]"});
}

TEST_F(HostileRanges, EtaAtItsBoundRunsAndReflectsAlmostEverything) {
  // eta = 1e9: transmittance at normal incidence 4/eta = 4e-9, so R carries
  // all but ~1e-8 of the light, in the simulator and in the exact model
  // (which once said R = 1 while the simulator said 100% truncated, R = 0).
  const std::string c = config("eta.yaml", with(kGood, "fiber: {", "fiber: {eta: 1e9, "));
  const Outcome o = fiberlab("run " + c + " --quiet -o " + path("out.h5"));
  ASSERT_EQ(o.status, 0) << o.err;
  const double r = python_value(path("out.h5"), "f['ledger/exited'][0, 0, 0] / f['tally/photons'][0]");
  EXPECT_GT(r, 1.0 - 1e-6);
  EXPECT_EQ(python_value(path("out.h5"), "f['ledger/truncated'][...].sum()"), 0.0);
  ASSERT_EQ(fiberlab("predict " + path("out.h5") + " --model exact -o " + path("p.h5")).status, 0);
  const double predicted = python_value(path("p.h5"), "f['prediction/probability'][0, 0, :, :, 0].sum()");
  EXPECT_NEAR(predicted, 1.0, 1e-3);
}

TEST_F(HostileRanges, EccentricityBelowNormalDoubles) {
  for (const char* e : {"1e-310", "2.2250738585072e-308", "0"}) {
    const std::string c = config("e.yaml", with(kGood, "fiber: {", std::string("fiber: {eccentricity: ") + e + ", "));
    expect_refused("run " + c + " -o " + path("out.h5"), {"fiber.eccentricity", "[2.2250738585072014e-308, 1]"});
  }
  expect_refused("predict " + shared("good.h5") + " --model marschner2003 --set eccentricity=1e-310 -o " +
                     path("p.h5"),
                 {"--set eccentricity=1e-310", "[2.2250738585072014e-308, 1]"});
}

TEST_F(HostileRanges, EccentricityAtItsBoundRunsWithTheLedgerBalanced) {
  // A ribbon 2^-511 thick: every quantity of the geometry stays finite, so
  // no photon is lost to NaN (at 1e-310 every one was "truncated").
  const std::string c =
      config("e.yaml", with(kGood, "fiber: {", "fiber: {eccentricity: 2.2250738585072014e-308, "));
  const Outcome o = fiberlab("run " + c + " --quiet -o " + path("out.h5"));
  ASSERT_EQ(o.status, 0) << o.err;
  const double total = python_value(
      path("out.h5"), "(f['ledger/exited'][0, :, 0].sum() + f['ledger/absorbed'][0, 0] + "
                      "f['ledger/truncated'][0, 0] + f['ledger/lost'][0, 0]) / f['tally/photons'][0]");
  EXPECT_NEAR(total, 1.0, 1e-12);
  EXPECT_LT(python_value(path("out.h5"), "f['ledger/truncated'][0, 0] / f['tally/photons'][0]"), 0.01);
  EXPECT_GT(python_value(path("out.h5"), "f['ledger/exited'][0, 0, 0] / f['tally/photons'][0]"), 0.0);
}

TEST_F(HostileRanges, ModelParametersOutOfTheirRanges) {
  const std::string p = "predict " + shared("good.h5") + " -o " + path("p.h5") + " --model ";
  expect_refused(p + "deon2011 --set beta_long=1e300", {"--set beta_long=1e300", "degrees in [0, 90]"});
  expect_refused(p + "deon2011 --set beta_azim=91", {"--set beta_azim=91", "degrees in [0, 90]"});
  expect_refused(p + "deon2011 --set alpha=-1e200", {"--set alpha=-1e200", "[-180, 180]"});
  expect_refused(p + "marschner2003 --set k_g=1e300", {"--set k_g=1e300", "[0, 10]"});
  expect_refused(p + "marschner2003 --set delta_h_m=2", {"--set delta_h_m=2", "[0, 1]"});
  expect_refused(p + "marschner2003 --set w_c=1e9", {"--set w_c=1e9", "[0, 180]"});
}

TEST_F(HostileRanges, SetKeyRepeated) {
  expect_refused("predict " + shared("good.h5") + " --model deon2011 --set beta_long=2 --set beta_long=3 -o " +
                     path("p.h5"),
                 {"--set beta_long=3", "already set by --set beta_long=2"});
  expect_refused("compare " + shared("good.h5") + " --model deon2011 --set lobes=3 --set 'lobes = 4'",
                 {"lobes is already set"});
}

// ------------------------------------------------------------ compare's verdict flags

TEST_F(HostileRanges, CompareFlagsOutOfRange) {
  const std::string c = "compare " + shared("good.h5") + " --model exact ";
  expect_refused(c + "--min-energy inf", {"--min-energy = inf", "[0, 1)"});
  expect_refused(c + "--min-energy nan", {"--min-energy = nan"});
  expect_refused(c + "--min-energy 1", {"--min-energy = 1", "would judge no lobe"});
  expect_refused(c + "--min-energy -1", {"--min-energy = -1"});
  expect_refused(c + "--max-chi2 nan", {"--max-chi2 = nan", "> 0"});
  expect_refused(c + "--max-chi2 0", {"--max-chi2 = 0", "> 0"});
  expect_refused(c + "--max-chi2 inf", {"--max-chi2 = inf"});
  expect_refused(c + "--model-error -1", {"--model-error = -1", "[0, 1]"});
  expect_refused(c + "--model-error nan", {"--model-error = nan"});
  expect_refused(c + "--min-effective inf", {"--min-effective = inf"});
}

TEST_F(HostileRanges, CompareThatJudgesNothingAcceptsNothing) {
  // Every lobe below --min-energy: "0 of 0 judged lobes accepted" must not
  // pass a gate (exit 1, saying why).
  const Outcome o = fiberlab("compare " + shared("good.h5") + " --model exact --min-energy 0.999");
  EXPECT_EQ(o.status, 1) << o.out << o.err;
  EXPECT_NE(o.out.find("0 of 0 judged lobes accepted"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("no lobe was judged"), std::string::npos) << o.out;
  EXPECT_NE(o.out.find("nothing is accepted, exit status 1"), std::string::npos) << o.out;
}

TEST_F(HostileRanges, FitKeysRepeated) {
  const std::string c = "compare " + shared("good.h5") + " --model deon2011 --fit ";
  expect_refused(c + "beta_long[0],beta_long[0]", {"beta_long[0] fits the same parameter as beta_long[0]"});
  expect_refused(c + "beta_long,beta_long[1]", {"beta_long[1] fits the same parameter as beta_long"});
  expect_refused(c + "scale_tilt,alpha[2]", {"alpha[2] fits the same parameter as scale_tilt"});
}

TEST_F(HostileRanges, PredictionWithNegativeOrNonFiniteProbabilities) {
  const std::string c = "compare " + shared("good.h5") + " --prediction ";
  expect_refused(c + crafted_prediction("neg.h5", "f['prediction/probability'][1, 2, 3, 4, 1] = -0.25"),
                 {"neg.h5: /prediction/probability holds -0.25 at flat index", "finite and >= 0"});
  expect_refused(c + crafted_prediction("nan.h5", "f['prediction/probability'][0, 0, 0, 0, 0] = np.nan"),
                 {"holds nan at flat index 0", "finite and >= 0"});
  expect_refused("info " + crafted_prediction("inf.h5", "f['prediction/probability'][0, 0, 0, 0, 0] = np.inf"),
                 {"holds inf at flat index 0"});
}

TEST_F(HostileRanges, PredictionDeclaringAHugeArrayIsCheckedAgainstTheResultFirst) {
  SKIP_UNDER_ADDRESS_LIMIT();
  // ~4 GB declared in a few KB: refused from the shape, before any allocation
  // (under a 1 GiB address-space limit, an allocation would fail instead).
  const std::string f = crafted_prediction(
      "huge.h5",
      "del f['prediction/probability']\n"
      "f.create_dataset('prediction/probability', shape=(2, 3, 9, 12, 800000), dtype='f8', "
      "chunks=(1, 1, 1, 1, 100000), compression='gzip')");
  EXPECT_LT(fs::file_size(f), 1u << 20);
  const auto before = listing();
  const Outcome o = run("(ulimit -v 1048576; " + std::string(FIBERLAB_BINARY) + " compare " + shared("good.h5") +
                        " --prediction " + f + ")");
  EXPECT_EQ(o.status, 2) << o.err;
  EXPECT_NE(o.err.find("800000 channels, the result has 2"), std::string::npos) << o.err;
  EXPECT_EQ(listing(), before);
}

// ------------------------------------------------------------ late refusals

TEST_F(HostileRanges, LongExitBlurListRefusedBeforeTheRun) {
  auto betas = [](int n) {
    std::string s = "[";
    for (int i = 0; i < n; ++i) s += (i ? ", " : "") + std::to_string(1 + i % 30);
    return s + "]";
  };
  const std::string too_long = config(
      "long.yaml", with(kGood, "{model: gaussian, beta_long: 5}", "{model: exit_blur, beta_long: " + betas(1025) + "}"));
  expect_refused("run " + too_long + " -o " + path("out.h5"),
                 {"roughness.beta_long", "has 1025 entries", "at most 1024"});
  // The longest list allowed is written and read back.
  const std::string longest = config(
      "longest.yaml", with(kGood, "{model: gaussian, beta_long: 5}", "{model: exit_blur, beta_long: " + betas(1024) + "}"));
  const Outcome o = fiberlab("run " + longest + " --quiet -o " + path("out.h5"));
  ASSERT_EQ(o.status, 0) << o.err;
  EXPECT_EQ(fiberlab("info " + path("out.h5")).status, 0);
  EXPECT_EQ(python_value(path("out.h5"), "len(f['roughness'].attrs['beta_long'])"), 1024.0);
}

TEST_F(HostileRanges, MemoryBudgetCheckedBeforeTheTalliesAreAllocated) {
  SKIP_UNDER_ADDRESS_LIMIT();
  // ~3 GiB of tallies under a 1.5 GiB address-space limit: the budget's one
  // line, not a bare "out of memory" from allocating them first.
  const std::string c = config("big.yaml", "photons: 1000\nfiber: {sigma_a: 0}\nsource: {theta_i: [10]}\n"
                                           "tally: {n_theta: 2500, n_phi: 2500, lobes: 4}\n");
  const auto before = listing();
  const Outcome o = run("(ulimit -v 1572864; " + std::string(FIBERLAB_BINARY) + " run " + c + " --threads 1 -o " +
                        path("out.h5") + ")");
  EXPECT_EQ(o.status, 2) << o.err;
  EXPECT_NE(o.err.find("the run needs"), std::string::npos) << o.err;
  EXPECT_EQ(o.err.find("out of memory"), std::string::npos) << o.err;
  EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << o.err;
  EXPECT_EQ(listing(), before);
}

TEST_F(HostileRanges, OutputNamesWithControlCharacters) {
  for (const char* name : {"a\nb.h5", "a\tb.h5", "a\rb.h5"}) {
    const std::string quoted = "'" + path(name) + "'";
    expect_refused("run " + shared("good.yaml") + " -o " + quoted, {"control character"});
    expect_refused("merge " + shared("good.h5") + " " + shared("good2.h5") + " -o " + quoted, {"control character"});
    expect_refused("predict " + shared("good.h5") + " --model exact -o " + quoted, {"control character"});
  }
  // The config's own output key says so too.
  const std::string c = config("nl.yaml", std::string(kGood) + "output: \"a\\nb.h5\"\n");
  expect_refused("run " + c, {"output", "control character"});
}

TEST_F(HostileRanges, OutputNamesTooLongForTheirDerivedNames) {
  // merge: the temporary .NAME.tmp-PID (13 bytes more) must fit NAME_MAX.
  const std::string ok(242 - 3, 'm'), too_long(243 - 3, 'm');
  ASSERT_EQ(fiberlab("merge " + shared("good.h5") + " " + shared("good2.h5") + " -o " + path(ok + ".h5")).status, 0);
  expect_refused("merge " + shared("good.h5") + " " + shared("good2.h5") + " -o " + path(too_long + ".h5"),
                 {"243 bytes", "NAME_MAX", "at most 242 bytes"});
  // run: its checkpoint OUT.checkpoint.h5 and that one's temporary name too
  // (a 240-byte output name once broke the first checkpoint).
  expect_refused("run " + shared("good.yaml") + " -o " + path(std::string(240 - 3, 'r') + ".h5"),
                 {".checkpoint.h5", "NAME_MAX"});
  expect_refused("run " + shared("good.yaml") + " -o " + path(std::string(300, 'r') + ".h5"), {"NAME_MAX"});
  const Outcome o = fiberlab("run " + shared("good.yaml") + " --quiet -o " + path(std::string(231 - 3, 'r') + ".h5"));
  EXPECT_EQ(o.status, 0) << o.err;
}

TEST_F(HostileRanges, AtlasConfigDuplicateKeysAndFiberOwnParameters) {
  const std::string base =
      "photons: 1000\ntally: {n_theta: 9, n_phi: 12, lobes: 4}\n"
      "sweep:\n  roughness: [{model: exit_blur, beta_long: 8, beta_azim: 15}]\n  theta_i: [25]\n"
      "models: [exact, deon2011]\n";
  expect_refused("atlas " + config("dup.yaml", base + "photons: 2000\n") + " -o " + path("a.h5"),
                 {"dup.yaml", "duplicate key photons"});
  expect_refused("atlas " + config("dup2.yaml", with(base, "theta_i: [25]", "theta_i: [25]\n  theta_i: [35]")) +
                     " -o " + path("a.h5"),
                 {"duplicate key sweep.theta_i"});
  expect_refused("atlas " + config("lobes.yaml", base + "model_parameters: {deon2011: {lobes: 3}}\n") + " -o " +
                     path("a.h5"),
                 {"model_parameters.deon2011.lobes", "tally.lobes"});
  expect_refused("atlas " + config("sigma.yaml", base + "model_parameters: {exact: {sigma_a: [0.1, 0.2]}}\n") +
                     " -o " + path("a.h5"),
                 {"model_parameters.exact.sigma_a", "fiber.sigma_a"});
  // Run configs: a key repeated at any depth.
  expect_refused("run " + config("rdup.yaml", with(kGood, "fiber: {", "fiber: {eta: 1.5, eta: 1.6, ")) + " -o " +
                     path("o.h5"),
                 {"duplicate key fiber.eta"});
}

}  // namespace
