// `--set KEY=VALUE` parsing, the model factory and `fiberlab predict`.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "analytic/model_factory.h"
#include "analytic/model_params.h"
#include "common/error.h"
#include "common/h5_file.h"
#include "common/units.h"

using namespace fiberlab;
using namespace fiberlab::analytic;

TEST(ModelParams, ParsesEveryKey) {
  ModelParams p;
  apply_settings(p, {"eta=1.6", "sigma_a=0.1,0.2,0.3,0.4", "beta_long=5,10", "beta_azim=7",
                     "alpha=-6,3,12", "absorption=chord", "longitudinal=two_theta_h", "roots=exact",
                     "eccentricity=0.85", "k_g=0.4", "w_c=10", "delta_eta=0.2", "delta_h_m=0.5",
                     "lobes=5", "quadrature_order=50", "r_fresnel=per_h", "max_order=30", "n_theta_d=specular"});
  EXPECT_EQ(p.eta, 1.6);
  EXPECT_EQ(p.sigma_a.size(), 4u);
  EXPECT_NEAR(p.beta_long[1], deg_to_rad(10.0), 1e-15);
  EXPECT_NEAR(p.alpha[0], deg_to_rad(-6.0), 1e-15);
  EXPECT_EQ(p.absorption, Absorption::Chord);
  EXPECT_TRUE(p.two_theta_h && p.exact_roots);
  EXPECT_NEAR(p.w_c, deg_to_rad(10.0), 1e-15);
  EXPECT_EQ(p.delta_h_m, 0.5);
  EXPECT_EQ(p.lobes, 5);
  EXPECT_EQ(p.quadrature_order, 50);
  EXPECT_FALSE(p.r_half_angle_fresnel);
  EXPECT_EQ(p.max_order, 30);
  EXPECT_TRUE(p.specular_theta_d);
  EXPECT_EQ(to_attributes(p).size(), 18u);
}

TEST(ModelParams, BadInputNamesTheKeyAndTheAllowedValues) {
  ModelParams p;
  for (const char* bad : {"eta=1", "eta=abc", "sigma_a=0.1,,0.2", "beta_long=-1", "absorption=foo",
                          "lobes=0", "lobes=2.5", "eccentricity=1.5", "nokey", "colour=red"}) {
    try {
      apply_setting(p, bad);
      ADD_FAILURE() << bad;
    } catch (const Error& e) {
      const std::string msg = e.what();
      const std::string key = std::string(bad).substr(0, std::string(bad).find('='));
      EXPECT_NE(msg.find(key), std::string::npos) << msg;
      EXPECT_NE(msg.find("allowed"), std::string::npos) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos);
    }
  }
  EXPECT_THROW(make_model("phong", p), Error);
  ModelParams q;
  q.beta_long = {deg_to_rad(5.0)};
  q.beta_azim = {deg_to_rad(5.0)};
  for (const auto& n : model_names()) EXPECT_EQ(make_model(n, q)->lobes(), 4);
}

TEST(Predict, WritesAPredictionFileOrNothing) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "fiberlab_test_predict";
  fs::create_directories(dir);
  const std::string cfg = std::string(FIBERLAB_SOURCE_DIR) + "/configs/smooth_circle.yaml";
  const std::string out = (dir / "pred.h5").string();
  fs::remove(out);
  const std::string bin = FIBERLAB_BINARY;
  int rc = std::system((bin + " predict " + cfg + " --model exact -o " + out + " 2>/dev/null").c_str());
  ASSERT_EQ(WEXITSTATUS(rc), 0);
  {
    const h5::File f = h5::File::open_read(out);
    EXPECT_EQ(f.attr_string("/", "format"), "fiber-prediction");
    EXPECT_EQ(f.attr_string("/prediction", "model"), "exact");
    h5::Dims dims;
    const auto p = f.read_doubles("/prediction/probability", &dims);
    ASSERT_EQ(dims.size(), 5u);
    double s = 0.0;
    for (double x : p) s += x;
    EXPECT_NEAR(s, static_cast<double>(dims[0]), 1e-8);  // sigma_a = 0: every configuration sums to 1
  }
  const std::string bad = (dir / "bad.h5").string();
  fs::remove(bad);
  rc = std::system((bin + " predict " + cfg + " --model deon2011 --set beta_long=x -o " + bad + " 2>/dev/null").c_str());
  EXPECT_EQ(WEXITSTATUS(rc), 2);
  EXPECT_FALSE(fs::exists(bad));
  rc = std::system((bin + " predict " + cfg + " --model nosuch -o " + bad + " 2>/dev/null").c_str());
  EXPECT_EQ(WEXITSTATUS(rc), 2);
  EXPECT_FALSE(fs::exists(bad));
}
