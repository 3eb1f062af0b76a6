// Hostile inputs: report
// folders never written through a planted link and never left half-written;
// checkpoints accepted only when their config, attributes and sums agree;
// damaged files (a flipped bit anywhere) give one line and exit 2, never a
// crash and never a silently changed config or sum; temporaries of a killed
// checkpoint write are removed by the next run.
//
// Fixtures are named Hostile* so that the sanitizer job (scripts/test_sanitize.sh,
// label "sanitize") runs them; BitFlipFuzz.FiveHundredEach, the long fuzz, is
// left to the normal suite.
#include <gtest/gtest.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "common/atomic_output.h"
#include "common/error.h"
#include "sim/store/checkpoint.h"
#include "sim/run/settings.h"
#include "sim/run/simulation.h"

namespace {

namespace fs = std::filesystem;

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif

struct Outcome {
  int status;  // exit status, or 128 + signal
  bool signalled;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

void spit(const fs::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
}

void replace_all(std::string& s, const std::string& from, const std::string& to) {
  for (std::size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
    s.replace(at, from.size(), to);
}

int lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

// A small run's config: 2 directions, 2 channels, 3 lobes, 9 x 12 bins.
constexpr const char* kConfig =
    "photons: 12288\nfiber: {sigma_a: [0.1, 0.2]}\nroughness: {model: gaussian, beta_long: 5}\n"
    "source: {theta_i: [10, 40]}\ntally: {n_theta: 9, n_phi: 12, lobes: 3}\n";

class Files : public ::testing::Test {
 protected:
  // good1.h5, good2.h5 (another seed), and a checkpoint of the first chunk
  // of every direction of good1's run (sim::write_checkpoint, as a run
  // interrupted after one chunk writes it), for every test of the binary.
  static void SetUpTestSuite() {
    shared_ = fs::temp_directory_path() / ("fiberlab_damaged_" + std::to_string(getpid()));
    fs::remove_all(shared_);
    fs::create_directories(shared_);
    spit(shared_ / "good.yaml", kConfig);
    for (const char* seed : {"1", "2"}) {
      const std::string cmd = std::string(FIBERLAB_BINARY) + " run " + (shared_ / "good.yaml").string() +
                              " --quiet --seed " + seed + " -o " + (shared_ / ("good" + std::string(seed) + ".h5")).string();
      ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    }
  }
  static void TearDownTestSuite() { fs::remove_all(shared_); }

  void SetUp() override {
    dir_ = shared_ / ::testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::create_directories(dir_);
  }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  static std::string good(int i) { return (shared_ / ("good" + std::to_string(i) + ".h5")).string(); }

  // A checkpoint whose run writes OUT (absolute, in this test's folder):
  // OUT's name with .checkpoint.h5.
  // Written in a child process: a writer's AtomicOutput installs signal
  // handlers for good (common/interrupt.h), which test_interrupt.cpp's tests
  // in this binary must not find installed.
  std::string make_checkpoint(const std::string& out) const {
    const std::string ck = fiberlab::sim::checkpoint_path(out);
    const pid_t child = fork();
    if (child == 0) {
      try {
        write_partial_checkpoint(out);
      } catch (...) {
        _exit(1);
      }
      _exit(0);
    }
    int status = 0;
    waitpid(child, &status, 0);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "writing " << ck;
    return ck;
  }

  static void write_partial_checkpoint(const std::string& out) {
    using namespace fiberlab::sim;
    Settings s = parse_settings_yaml(kConfig, "fuzz.yaml");
    s.seed = 1;
    s.output = out;
    Settings part = s;
    part.photons = Simulation::kChunk;
    const Simulation whole(s), first(part);
    RunProgress state = first.start();
    RunControl control;
    control.threads = 1;
    if (first.run(state, control) != RunOutcome::Finished) throw fiberlab::Error("interrupted");
    state.done.assign(state.done.size(), 0);
    write_checkpoint(checkpoint_path(out), whole, state, 0.0);
  }

  Outcome run(const std::string& command, const std::string& env = "") const {
    const std::string cmd = env + " " + command + " >" + path("stdout") + " 2>" + path("stderr");
    const int raw = std::system(cmd.c_str());
    return {WIFEXITED(raw) ? WEXITSTATUS(raw) : 128 + WTERMSIG(raw), !WIFEXITED(raw), slurp(path("stdout")),
            slurp(path("stderr"))};
  }
  Outcome fiberlab(const std::string& args, const std::string& env = "") const {
    return run(std::string(FIBERLAB_BINARY) + " " + args, env);
  }

  // Alters `file` with Python statements on `f` (h5py.File opened r+; numpy as np).
  void edit(const std::string& file, const std::string& python) const {
    spit(path("edit.py"), "import h5py, numpy as np, sys\nf = h5py.File(sys.argv[1], 'r+')\n" + python +
                              "\nf.close()\n");
    const Outcome o = run("/usr/bin/python3 " + path("edit.py") + " " + file);
    ASSERT_EQ(o.status, 0) << o.err;
  }

  void expect_refused(const Outcome& o, std::initializer_list<std::string> needles, const std::string& what) const {
    EXPECT_EQ(o.status, 2) << what << "\n" << o.err;
    EXPECT_EQ(lines(o.err), 1) << what << "\n" << o.err;
    for (const std::string& n : needles) EXPECT_NE(o.err.find(n), std::string::npos) << "missing '" << n << "' in " << o.err;
    std::cout << "    " << o.err;
  }

  // Names in a folder.
  static std::set<std::string> listing(const fs::path& d) {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(d)) names.insert(e.path().filename().string());
    return names;
  }

  static inline fs::path shared_;
  fs::path dir_;
};

// ------------------------------------------------------------ damaged files

using HostileDamage = Files;

// The layout written: superblock version 2 or 3 (HDF5 1.10's "latest" bounds,
// whose metadata carries checksums), read by h5py, with the attribute digest;
// a copy in the oldest layout (superblock 0, no checksums) made by h5py is
// still read, and gives the same `info`.
TEST_F(HostileDamage, LatestLayoutWrittenAndOldLayoutStillRead) {
  const std::string bytes = slurp(good(1));
  ASSERT_GT(bytes.size(), 9u);
  EXPECT_EQ(bytes.substr(0, 8), "\x89HDF\r\n\x1a\n");
  EXPECT_GE(static_cast<int>(bytes[8]), 2) << "superblock version";
  const std::string old = path("old.h5");
  spit(path("to_old_layout.py"),
       "import h5py, sys\n"
       "with h5py.File(sys.argv[1], 'r') as a, h5py.File(sys.argv[2], 'w', libver='earliest') as b:\n"
       "    for k, v in a.attrs.items(): b.attrs[k] = v\n"
       "    for name in a: a.copy(a[name], b, name=name)\n");
  ASSERT_EQ(run("/usr/bin/python3 " + path("to_old_layout.py") + " " + good(1) + " " + old).status, 0);
  EXPECT_EQ(static_cast<int>(slurp(old)[8]), 0) << "h5py did not write the old layout";
  const Outcome a = fiberlab("info " + good(1)), b = fiberlab("info " + old);
  EXPECT_EQ(a.status, 0) << a.err;
  EXPECT_EQ(b.status, 0) << b.err;
  std::string want = a.out, got = b.out;
  replace_all(want, good(1), "F");
  replace_all(got, old, "F");
  EXPECT_EQ(got, want);
}

// One character of config_yaml changed in the file's bytes (eta, as a flipped
// bit in HDF5's global heap, which has no checksum, would): every reader
// refuses it with one line, through the attribute digest.
TEST_F(HostileDamage, ChangedConfigTextIsRefusedByEveryReader) {
  std::string bytes = slurp(good(1));
  const std::size_t at = bytes.find("eta: 1.55");
  ASSERT_NE(at, std::string::npos) << "config_yaml not stored as plain text";
  bytes[at + 8] = '7';  // 1.55 -> 1.57
  const std::string f = path("eta.h5");
  spit(f, bytes);
  for (const std::string& args : {"info " + f, "merge " + f + " " + good(2) + " -o " + path("m.h5"),
                                  "energy " + f + " --models deon2011",
                                  "compare " + f + " --model deon2011"})
    expect_refused(fiberlab(args), {f, "attribute_digest"}, args);
  EXPECT_FALSE(fs::exists(path("m.h5")));
  // fiberlab.load (the Python module next to the binary's build folder): fiberlab.Error.
  const fs::path module = fs::path(FIBERLAB_BINARY).parent_path().parent_path() / "python";
  bool built = false;  // the compiled extension (the sanitizer job builds none)
  if (fs::is_directory(module / "fiberlab"))
    for (const auto& e : fs::directory_iterator(module / "fiberlab"))
      built = built || e.path().filename().string().starts_with("_fiberlab.");
  if (!built) {
    std::cout << "    no Python module built at " << module << ": fiberlab.load not tried\n";
    return;
  }
  spit(path("load.py"), "import sys, fiberlab\ntry:\n    fiberlab.load(sys.argv[1])\nexcept fiberlab.Error as e:\n"
                        "    print(e)\n    sys.exit(2)\n");
  const Outcome py = run("cd / && PYTHONPATH=" + module.string() + " /usr/bin/python3 " + path("load.py") + " " + f);
  EXPECT_EQ(py.status, 2) << py.out << py.err;
  EXPECT_NE(py.out.find("attribute_digest"), std::string::npos) << py.out;
}

// Files in the old layout (no checksums) are read in a child process first
// (h5::probe_file): damage that kills HDF5 there is one line here. The
// issue's crash came from a flipped bit in the global heap (where the
// variable-length strings live); here each byte of an old-layout copy's
// global heap header (the collection's signature, version and size) is set
// to 0x00, 0x7f and 0xff in turn: `info` ends with exit 0 or 2, never a signal.
TEST_F(HostileDamage, DestroyedGlobalHeapNeverCrashes) {
  const std::string old = path("old.h5");
  spit(path("to_old_layout.py"),
       "import h5py, sys\n"
       "with h5py.File(sys.argv[1], 'r') as a, h5py.File(sys.argv[2], 'w', libver='earliest') as b:\n"
       "    for k, v in a.attrs.items(): b.attrs[k] = v\n"
       "    for name in a: a.copy(a[name], b, name=name)\n");
  ASSERT_EQ(run("/usr/bin/python3 " + path("to_old_layout.py") + " " + good(1) + " " + old).status, 0);
  const std::string bytes = slurp(old);
  std::size_t gcol = bytes.find("GCOL");
  ASSERT_NE(gcol, std::string::npos);
  int crashed_before = 0;
  for (std::size_t i = gcol + 4; i < gcol + 24 && i < bytes.size(); ++i)
    for (unsigned char v : {0x00, 0xff, 0x7f}) {
      std::string damaged = bytes;
      damaged[i] = static_cast<char>(v);
      const std::string f = path("gcol.h5");
      spit(f, damaged);
      const Outcome o = fiberlab("info " + f);
      EXPECT_FALSE(o.signalled) << "byte " << i << " = " << int(v) << ": " << o.err;
      EXPECT_TRUE(o.status == 0 || o.status == 2) << o.status << " " << o.err;
      if (o.status == 2) {
        EXPECT_EQ(lines(o.err), 1) << o.err;
        if (o.err.find("crashed the HDF5 library") != std::string::npos) ++crashed_before;
      }
    }
  std::cout << "    global heap damage that crashed HDF5 in the probe: " << crashed_before << " of 60\n";
}

// ------------------------------------------------------------ checkpoints

using HostileCheckpoint = Files;

TEST_F(HostileCheckpoint, ConsistentCheckpointResumes) {
  const std::string out = path("r.h5"), ck = make_checkpoint(out);
  const Outcome o = fiberlab("run --resume " + ck + " --quiet");
  EXPECT_EQ(o.status, 0) << o.err;
  EXPECT_TRUE(fs::exists(out));
  EXPECT_FALSE(fs::exists(ck));
}

// Each edit made through h5py (so HDF5's checksums are right), with the
// attribute digest removed where an attribute is edited (an editor that knows
// the format): the checkpoint's own consistency refuses it.
TEST_F(HostileCheckpoint, InconsistentCheckpointsAreRefused) {
  struct Case {
    const char* name;
    std::string python;
    std::vector<std::string> needles;
  };
  const std::string nodigest = "\ndel f.attrs['attribute_digest']";
  const std::vector<Case> cases = {
      {"eta", "f.attrs['config_yaml'] = f.attrs['config_yaml'].replace('eta: 1.55', 'eta: 1.57')" + nodigest,
       {"config_digest"}},
      {"fiber_attr", "f['fiber'].attrs['eta'] = 1.57" + nodigest, {"/fiber@eta"}},
      {"raised_photons",
       "p = f['tally/photons'][()]; p[0] += 4096; f['tally/photons'][...] = p\n"
       "n = f['checkpoint/next_photon'][()]; n[0] += 4096; f['checkpoint/next_photon'][...] = n",
       {"ledger does not balance"}},
      {"count_moved", "c = f['tally/count'][()]; i = np.argmax(c); c.flat[i] -= 1; c.flat[(i + 1) % c.size] += 1\n"
                      "f['tally/count'][...] = c",
       {"sums_digest"}},
      {"count_over", "c = f['tally/count'][()]; c.flat[0] = 10**9; f['tally/count'][...] = c", {"more than"}},
      {"done_unstarted",
       "n = f['checkpoint/next_photon'][()]; n[1] = 0; f['checkpoint/next_photon'][...] = n\n"
       "p = f['tally/photons'][()]; p[1] = 0; f['tally/photons'][...] = p\n"
       "d = f['checkpoint/done'][()]; d[1] = 1; f['checkpoint/done'][...] = d",
       {"direction 1", "done 1"}},
      {"no_digest", "del f.attrs['attribute_digest']", {"attribute_digest is missing"}},
      {"no_config_digest", "del f['checkpoint'].attrs['config_digest']" + nodigest, {"config_digest is missing"}},
  };
  for (const Case& c : cases) {
    const std::string out = path(std::string(c.name) + ".h5"), ck = make_checkpoint(out);
    edit(ck, c.python);
    const auto before = listing(dir_);
    std::vector<std::string> needles = c.needles;
    needles.push_back(ck);
    const Outcome o = fiberlab("run --resume " + ck + " --quiet");
    EXPECT_EQ(o.status, 2) << c.name << "\n" << o.err;
    EXPECT_EQ(lines(o.err), 1) << c.name << "\n" << o.err;
    for (const std::string& n : needles)
      EXPECT_NE(o.err.find(n), std::string::npos) << c.name << ": missing '" << n << "' in " << o.err;
    EXPECT_FALSE(fs::exists(out)) << c.name;
    EXPECT_EQ(listing(dir_), before) << c.name;
    std::cout << "    " << c.name << ": " << o.err;
  }
}

// A SIGKILL during a checkpoint write leaves .NAME.tmp-PID: the next run of
// that output removes it (a regular file of a process that is gone), and
// leaves a symbolic link of that pattern, and what it points to, alone.
TEST_F(HostileCheckpoint, StaleCheckpointTemporaryIsRemovedByTheNextRun) {
  spit(path("c.yaml"), kConfig);
  const std::string out = path("r.h5");
  const fs::path stale = dir_ / ".r.checkpoint.h5.tmp-999999999";
  const fs::path link = dir_ / ".r.checkpoint.h5.tmp-999999998";
  spit(stale, "half-written");
  spit(path("precious"), "keep me");
  fs::create_symlink(path("precious"), link);
  const Outcome o = fiberlab("run " + path("c.yaml") + " --quiet -o " + out);
  EXPECT_EQ(o.status, 0) << o.err;
  EXPECT_FALSE(fs::exists(fs::symlink_status(stale)));
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(slurp(path("precious")), "keep me");
}

// The temporary's name is predictable (.NAME.tmp-PID): a link planted there
// is removed, never written through, whatever then writes the temporary.
TEST_F(HostileCheckpoint, LinkPlantedAtTheTemporaryNameIsNotFollowed) {
  const std::string target = path("out.h5");
  spit(path("precious"), "keep me");
  // In a child (see make_checkpoint), which plants the link at its own name.
  const pid_t child = fork();
  if (child == 0) {
    const fs::path planted = dir_ / (".out.h5.tmp-" + std::to_string(getpid()));
    fs::create_symlink(path("precious"), planted);
    fiberlab::AtomicOutput out(target);
    const bool ok = out.temp_path() == planted.string() && !fs::is_symlink(planted);
    std::ofstream(out.temp_path()) << "written";
    out.commit();
    _exit(ok ? 0 : 1);
  }
  int status = 0;
  waitpid(child, &status, 0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "the temporary was not made anew";
  EXPECT_EQ(slurp(path("precious")), "keep me");
  EXPECT_EQ(slurp(target), "written");
}

// ------------------------------------------------------------ report folders

using HostileReport = Files;

// A stand-in for scripts/plot_report.py (its contract: KIND DIR, files into
// DIR): writes a PNG and report.html, then exits with `status`.
std::string fake_plot_script(const fs::path& dir, int status) {
  const fs::path p = dir / ("plot_" + std::to_string(status) + ".py");
  spit(p, "import os, sys\nd = sys.argv[2]\n"
          "open(os.path.join(d, 'compare_a.png'), 'wb').write(b'png')\n"
          "open(os.path.join(d, 'report.html'), 'w').write('<html></html>')\n"
          "print('plotted')\nsys.exit(" + std::to_string(status) + ")\n");
  return p.string();
}

TEST_F(HostileReport, PlantedLinksAreRefusedAndTheirTargetsKept) {
  const std::string victim = path("victim");
  for (const auto& [name, status] : std::vector<std::pair<std::string, int>>{
           {"plot_log.txt", 1}, {"report.html", 0}, {"compare_a.png", 0}, {"metrics.json", 0}}) {
    const fs::path rep = dir_ / ("rep_" + std::to_string(status) + name);
    fs::create_directories(rep);
    spit(victim, "do not touch");
    fs::create_symlink(victim, rep / name);
    const auto before = listing(rep);
    const std::string env = "FIBERLAB_PYTHON=/usr/bin/python3 FIBERLAB_PLOT_SCRIPT=" + fake_plot_script(dir_, status);
    const Outcome o = fiberlab("compare " + good(1) + " --model deon2011 --report " + rep.string(), env);
    expect_refused(o, {rep.string(), name, "symbolic link"}, name);
    EXPECT_EQ(slurp(victim), "do not touch") << name;
    EXPECT_EQ(listing(rep), before) << name << ": the folder changed";
  }
}

TEST_F(HostileReport, CompleteReportHasNoStagingLeft) {
  const fs::path rep = dir_ / "a" / "rep";
  const std::string env = "FIBERLAB_PYTHON=/usr/bin/python3 FIBERLAB_PLOT_SCRIPT=" + fake_plot_script(dir_, 0);
  const Outcome o = fiberlab("compare " + good(1) + " --model deon2011 --report " + rep.string(), env);
  EXPECT_TRUE(o.status == 0 || o.status == 1) << o.err;  // the verdict
  EXPECT_EQ(listing(rep), (std::set<std::string>{"compare_a.png", "metrics.csv", "metrics.json", "report.html",
                                                 "report.md", "report_data.h5"}));
  // A failed plot: the report says so, and keeps the script's log.
  const Outcome f = fiberlab("compare " + good(1) + " --model deon2011 --report " + rep.string(),
                             "FIBERLAB_PYTHON=/usr/bin/python3 FIBERLAB_PLOT_SCRIPT=" + fake_plot_script(dir_, 1));
  EXPECT_TRUE(f.status == 0 || f.status == 1) << f.err;
  EXPECT_EQ(slurp(rep / "plot_log.txt"), "plotted\n");
  EXPECT_FALSE(fs::exists(rep / "report.html")) << "a page of the earlier report";
  EXPECT_NE(slurp(rep / "report.md").find("plots failed"), std::string::npos);
}

// A disk that fills during the report: exit 2, one line naming the report's
// file (not the staging folder), nothing left in the full folder.
TEST_F(HostileReport, DiskFullLeavesNoPartialFolder) {
  if (geteuid() != 0) GTEST_SKIP() << "mounting a small tmpfs needs root";
  const fs::path small = dir_ / "small";
  fs::create_directories(small);
  for (const char* size : {"4k", "16k"}) {
    if (mount("tmpfs", small.c_str(), "tmpfs", 0, (std::string("size=") + size).c_str()) != 0)
      GTEST_SKIP() << "cannot mount a tmpfs here (" << std::strerror(errno) << ")";
    const std::string rep = (small / "rep").string();
    const Outcome o = fiberlab("compare " + good(1) + " --model deon2011 --report " + rep,
                               "FIBERLAB_PYTHON=/usr/bin/python3 FIBERLAB_PLOT_SCRIPT=" + fake_plot_script(dir_, 0));
    expect_refused(o, {rep + "/", "No space left on device"}, size);  // names the report's file
    EXPECT_EQ(o.err.find(".report-staging"), std::string::npos) << o.err;
    EXPECT_TRUE(fs::is_empty(small)) << size << ": left behind in the full folder";
    umount(small.c_str());
  }
}

// ------------------------------------------------------------ bit-flip fuzz

// Flips `n` random bits (fixed seed) of a file, one copy each, and runs
// `command(copy)`; every run must end by exit 0 with `expected(copy)` equal to
// the undamaged file's (the flip hit bytes nobody reads), or exit 2 with one
// line, never a signal. Returns how many were refused.
struct FuzzTally {
  int refused = 0, same = 0;
};

class Fuzz : public Files {
 protected:
  // A result file: info and merge (merged with good2) of each damaged copy.
  FuzzTally fuzz_result(int n, std::uint64_t seed) {
    const std::string bytes = slurp(good(1));
    const std::string f = path("damaged.h5"), merged = path("merged.h5"), ref = path("ref_merged.h5");
    const std::string info_want = normalized(fiberlab("info " + good(1)).out, good(1));
    EXPECT_EQ(fiberlab("merge " + good(1) + " " + good(2) + " -o " + ref).status, 0);
    const std::string merge_want = normalized(fiberlab("info " + ref).out, ref);
    std::mt19937_64 rng(seed);
    FuzzTally t;
    for (int i = 0; i < n; ++i) {
      const std::size_t bit = rng() % (bytes.size() * 8);
      std::string damaged = bytes;
      damaged[bit / 8] = static_cast<char>(damaged[bit / 8] ^ (1 << (bit % 8)));
      spit(f, damaged);
      const std::string what = "result, bit " + std::to_string(bit);
      const Outcome info = fiberlab("info " + f);
      judge(info, what + ", info", [&] { return normalized(info.out, f) == info_want; }, t);
      fs::remove(merged);
      const Outcome m = fiberlab("merge " + f + " " + good(2) + " -o " + merged);
      judge(m, what + ", merge", [&] { return normalized(fiberlab("info " + merged).out, merged) == merge_want; }, t);
    }
    return t;
  }

  // A checkpoint: --resume of each damaged copy, whose output must equal the
  // undamaged checkpoint's resumed output.
  FuzzTally fuzz_checkpoint(int n, std::uint64_t seed) {
    const std::string out = path("r.h5"), ck = make_checkpoint(out);
    const std::string bytes = slurp(ck);
    EXPECT_EQ(fiberlab("run --resume " + ck + " --quiet").status, 0);
    const std::string want = normalized(fiberlab("info " + out).out, out);
    std::mt19937_64 rng(seed);
    FuzzTally t;
    for (int i = 0; i < n; ++i) {
      const std::size_t bit = rng() % (bytes.size() * 8);
      std::string damaged = bytes;
      damaged[bit / 8] = static_cast<char>(damaged[bit / 8] ^ (1 << (bit % 8)));
      fs::remove(out);
      spit(ck, damaged);
      const Outcome o = fiberlab("run --resume " + ck + " --quiet");
      judge(o, "checkpoint, bit " + std::to_string(bit), [&] { return normalized(fiberlab("info " + out).out, out) == want; }, t);
      fs::remove(ck);
    }
    return t;
  }

 private:
  // `info` output with the file's path and its creation time taken out.
  static std::string normalized(std::string s, const std::string& file) {
    replace_all(s, file, "F");
    std::string out;
    std::istringstream in(s);
    for (std::string line; std::getline(in, line);)
      if (line.find("created") == std::string::npos) out += line + "\n";
    return out;
  }

  template <class Same>
  void judge(const Outcome& o, const std::string& what, Same same, FuzzTally& t) {
    EXPECT_FALSE(o.signalled) << what << ": killed by a signal: " << o.err;
    if (o.status == 2) {
      EXPECT_EQ(lines(o.err), 1) << what << ": " << o.err;
      ++t.refused;
    } else {
      EXPECT_EQ(o.status, 0) << what << ": " << o.err;
      EXPECT_TRUE(same()) << what << ": accepted with a different output";
      ++t.same;
    }
  }
};

using HostileFuzz = Fuzz;

// The sanitizer job's share: fewer flips (each run is ~10x slower there).
TEST_F(HostileFuzz, BitFlipsInAResultAndACheckpoint) {
  const int n = kSanitized ? 10 : 30;
  const FuzzTally r = fuzz_result(n, 32), c = fuzz_checkpoint(n, 33);
  std::cout << "    result (info and merge of each copy): " << r.refused << " refused, " << r.same
            << " read as undamaged; checkpoint (--resume): " << c.refused << " refused, " << c.same
            << " resumed as undamaged\n";
}

using BitFlipFuzz = Fuzz;

TEST_F(BitFlipFuzz, FiveHundredEach) {
  const FuzzTally r = fuzz_result(500, 3201), c = fuzz_checkpoint(500, 3202);
  std::cout << "    result (info and merge of each copy): " << r.refused << " refused, " << r.same
            << " read as undamaged; checkpoint (--resume): " << c.refused << " refused, " << c.same
            << " resumed as undamaged\n";
}

}  // namespace
