// The command line's handling of bad input: a one-line
// error naming the field and the allowed range, a non-zero exit, and no
// output file. Runs the real `fiberlab` program.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include "tests/unique_temp_dir.h"

namespace {

namespace fs = std::filesystem;

struct Outcome {
  int status;
  std::string out, err;
};

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fiberlab::test_support::unique_temp_dir(
        "fiberlab_cli_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  void write(const std::string& name, const std::string& text) const {
    std::ofstream(path(name)) << text;
  }

  Outcome fiberlab(const std::string& args) const {
    const std::string cmd = std::string(FIBERLAB_BINARY) + " " + args + " >" + path("stdout") +
                            " 2>" + path("stderr");
    const int raw = std::system(cmd.c_str());
    auto slurp = [](const std::string& p) {
      std::ifstream f(p);
      std::stringstream s;
      s << f.rdbuf();
      return s.str();
    };
    return {WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, slurp(path("stdout")), slurp(path("stderr"))};
  }

  // A bad run: non-zero exit, one line on stderr containing every `needle`,
  // and no result file (nor temporary file) left behind.
  void expect_refused(const std::string& args, std::initializer_list<std::string> needles) {
    const Outcome o = fiberlab(args);
    EXPECT_NE(o.status, 0) << args;
    EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << o.err;
    for (const std::string& n : needles) EXPECT_NE(o.err.find(n), std::string::npos) << o.err;
    for (const auto& e : fs::directory_iterator(dir_)) {
      const std::string name = e.path().filename().string();
      EXPECT_TRUE(name == "stdout" || name == "stderr" || name.ends_with(".yaml"))
          << "left behind: " << name;
    }
  }

  static constexpr const char* kGood =
      "photons: 20000\nseed: 3\noutput: good.h5\n"
      "fiber: {eta: 1.55, sigma_a: [0.1, 0.2]}\n"
      "roughness: {model: gaussian, beta_long: 5}\n"
      "source: {theta_i: [10, 40]}\n"
      "tally: {n_theta: 18, n_phi: 36}\n";

  fs::path dir_;
};

TEST_F(Cli, RunInfoMergeSucceed) {
  write("good.yaml", kGood);
  const Outcome run = fiberlab("run " + path("good.yaml") + " -o " + path("a.h5") + " --threads 2");
  ASSERT_EQ(run.status, 0) << run.err;
  EXPECT_TRUE(fs::exists(path("a.h5")));
  EXPECT_NE(run.out.find("absorbed"), std::string::npos);
  ASSERT_EQ(fiberlab("run " + path("good.yaml") + " -o " + path("b.h5") + " --seed 4 --quiet").status, 0);
  const Outcome info = fiberlab("info " + path("a.h5"));
  EXPECT_EQ(info.status, 0) << info.err;
  EXPECT_NE(info.out.find("TRT"), std::string::npos);
  const Outcome merge = fiberlab("merge " + path("a.h5") + " " + path("b.h5") + " -o " + path("c.h5"));
  EXPECT_EQ(merge.status, 0) << merge.err;
  EXPECT_TRUE(fs::exists(path("c.h5")));
  // Merging a file with itself repeats a seed: refused, no output.
  EXPECT_NE(fiberlab("merge " + path("a.h5") + " " + path("a.h5") + " -o " + path("d.h5")).status, 0);
  EXPECT_FALSE(fs::exists(path("d.h5")));
}

// Files whose settings differ are refused with the first line of their
// configs that differs (here the estimator's exit_normals), and no output.
TEST_F(Cli, MergeNamesTheSettingThatDiffers) {
  const std::string ev = std::string(kGood) + "estimator: expected_value\n";
  write("four.yaml", ev + "exit_normals: 4\n");
  write("eight.yaml", ev + "exit_normals: [8, 2]\n");
  ASSERT_EQ(fiberlab("run " + path("four.yaml") + " -o " + path("four.h5") + " --quiet").status, 0);
  ASSERT_EQ(fiberlab("run " + path("eight.yaml") + " -o " + path("eight.h5") + " --seed 4 --quiet").status, 0);
  const Outcome o = fiberlab("merge " + path("four.h5") + " " + path("eight.h5") + " -o " + path("both.h5"));
  EXPECT_EQ(o.status, 2) << o.err;
  EXPECT_EQ(std::count(o.err.begin(), o.err.end(), '\n'), 1) << o.err;
  EXPECT_NE(o.err.find("eight.h5 has `exit_normals: [8, 2]`"), std::string::npos) << o.err;
  EXPECT_NE(o.err.find("four.h5 `exit_normals: [4]`"), std::string::npos) << o.err;
  EXPECT_FALSE(fs::exists(path("both.h5")));
}

TEST_F(Cli, MissingConfigFile) {
  expect_refused("run " + path("nope.yaml"), {"nope.yaml"});
}

TEST_F(Cli, MalformedYaml) {
  write("bad.yaml", "photons: [1, 2\nfiber: {eta: 1.5\n");
  expect_refused("run " + path("bad.yaml") + " -o " + path("x.h5"), {"bad.yaml"});
}

TEST_F(Cli, OutOfRangeValueNamesFieldAndRange) {
  write("bad.yaml", "photons: 100\nfiber: {eta: 0.9}\n");
  expect_refused("run " + path("bad.yaml") + " -o " + path("x.h5"), {"fiber.eta", "0.9", "(1, 1e9]"});
}

TEST_F(Cli, WrongType) {
  write("bad.yaml", "photons: many\n");
  expect_refused("run " + path("bad.yaml") + " -o " + path("x.h5"), {"photons"});
}

TEST_F(Cli, UnknownKey) {
  write("bad.yaml", "photons: 100\nfiber: {eta: 1.55, colour: red}\n");
  expect_refused("run " + path("bad.yaml") + " -o " + path("x.h5"), {"colour"});
}

TEST_F(Cli, UnwritableOutput) {
  write("good.yaml", kGood);
  expect_refused("run " + path("good.yaml") + " -o " + path("no/such/folder/out.h5"),
                 {"no/such/folder"});
}

TEST_F(Cli, BadFlag) {
  write("good.yaml", kGood);
  expect_refused("run " + path("good.yaml") + " -o " + path("x.h5") + " --photons 0",
                 {"--photons", ">= 1"});
}

TEST_F(Cli, InfoOnMissingOrForeignFile) {
  write("notes.yaml", "hello: 1\n");
  expect_refused("info " + path("missing.h5"), {"missing.h5"});
  expect_refused("info " + path("notes.yaml"), {"notes.yaml"});
}

}  // namespace
