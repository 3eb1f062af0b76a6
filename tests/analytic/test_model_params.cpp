// `--set KEY=VALUE` parsing, the model factory and `fiberlab predict`.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>

#include "analytic/deon2011.h"
#include "analytic/marschner2003.h"
#include "analytic/model_registry.h"
#include "analytic/smooth_cylinder.h"
#include "common/error.h"
#include "common/h5_file.h"
#include "common/units.h"

using namespace fiberlab;
using namespace fiberlab::analytic;

// Every key of every model's table parses a good value, and its default.
TEST(ModelParams, EveryTableKeyParses) {
  const std::map<std::string, std::string> good{
      {"eta", "1.6"}, {"sigma_a", "0.1,0.2,0.3,0.4"}, {"beta_long", "5,10"}, {"beta_azim", "7"},
      {"alpha", "-6,3,12"}, {"absorption", "chord"}, {"longitudinal", "two_theta_h"}, {"roots", "exact"},
      {"eccentricity", "0.85"}, {"k_g", "0.4"}, {"w_c", "10"}, {"delta_eta", "0.2"}, {"delta_h_m", "0.5"},
      {"lobes", "5"}, {"quadrature_order", "50"}, {"r_fresnel", "per_h"}, {"max_order", "30"},
      {"n_theta_d", "specular"}, {"beta_m", "0.4"}, {"beta_n", "0.6"}};
  // Keys whose meaning is the model's own (chiang2016's alpha is the tilt itself).
  const std::map<std::string, std::string> own{
      {"chiang2016 alpha", "3"},          {"chiang2016 mp", "pbrt_v4"},
      {"huang2022 roughness", "0.2"},
      {"huang2022 tilt", "3"},            {"huang2022 lobe_scale", "1,0.5,2"},
      {"huang2022 form", "cycles_eval"},
      {"huang2022 masking", "correlated"}, {"huang2022 flux", "macro"},
      {"huang2022 residual", "cycles_eval"},
      {"huang2022 quadrature_points", "65536"}, {"huang2022 quadrature_photons", "1e+06"}};
  for (const ModelInfo& m : registered_models()) {
    ModelParameters p = default_params(m.name);
    for (const ParamSpec& spec : m.params) {
      const auto o = own.find(m.name + " " + spec.key);
      ASSERT_TRUE(good.count(spec.key) || o != own.end()) << m.name << " " << spec.key;
      const std::string value = o != own.end() ? o->second : good.at(spec.key);
      apply_setting(m.name, p, spec.key + "=" + value);
      EXPECT_EQ(spec.show(p), value) << m.name << " " << spec.key;
    }
    EXPECT_EQ(param_attributes(m.name, p).size(), m.params.size());
  }
  ModelParameters p = default_params("deon2011");
  apply_setting("deon2011", p, "beta_long=5,10");
  EXPECT_NEAR(p.as<Deon2011Params>().beta_long[1], deg_to_rad(10.0), 1e-15);
}

// The defaults that matter: the exact model is exact (chord absorption);
// Marschner's caustic parameters are Table 1's.
TEST(ModelParams, DefaultsAreTheModelsOwn) {
  EXPECT_EQ(default_params("exact").as<ExactParams>().absorption, Absorption::Chord);
  EXPECT_EQ(default_params("deon2011").as<Deon2011Params>().absorption, Absorption::Published);
  const Marschner2003Params m = default_params("marschner2003").as<Marschner2003Params>();
  EXPECT_EQ(m.absorption, Absorption::Published);
  EXPECT_NEAR(m.w_c, deg_to_rad(10.0), 1e-15);
  EXPECT_EQ(m.k_g, 0.5);
  EXPECT_EQ(m.delta_eta, 0.3);
  EXPECT_EQ(m.delta_h_m, 0.5);
}

TEST(ModelParams, BadInputNamesTheKeyAndTheAllowedValues) {
  for (const char* bad : {"eta=1", "eta=abc", "sigma_a=0.1,,0.2", "beta_long=-1", "absorption=foo",
                          "lobes=0", "lobes=2.5", "nokey", "colour=red"}) {
    ModelParameters p = default_params("deon2011");
    try {
      apply_setting("deon2011", p, bad);
      ADD_FAILURE() << bad;
    } catch (const Error& e) {
      const std::string msg = e.what();
      const std::string key = std::string(bad).substr(0, std::string(bad).find('='));
      EXPECT_NE(msg.find(key), std::string::npos) << msg;
      EXPECT_NE(msg.find("allowed"), std::string::npos) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos);
    }
  }
  ModelParameters p;
  EXPECT_THROW(make_model("phong", p), Error);
  for (const auto& n : model_names()) {
    ModelParameters q = default_params(n);
    for (const char* width : {"beta_long=5", "beta_azim=5"})
      if (find_param(model_info(n).params, std::string(width).substr(0, 9))) apply_setting(n, q, width);
    EXPECT_EQ(make_model(n, q)->lobes(), 4);
  }
}

// A key the model does not use is refused, naming the key and listing the
// model's own keys.
TEST(ModelParams, KeyOfAnotherModelIsRefused) {
  ModelParameters p = default_params("exact");
  try {
    apply_setting("exact", p, "k_g=5");
    ADD_FAILURE();
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("k_g"), std::string::npos) << msg;
    EXPECT_NE(msg.find("eta, sigma_a, absorption, lobes"), std::string::npos) << msg;
  }
  EXPECT_THROW(apply_setting("deon2011", p, "w_c=10"), Error);
  EXPECT_THROW(apply_setting("marschner2003", p, "beta_azim=10"), Error);
}

TEST(Predict, WritesAPredictionFileOrNothing) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("fiberlab_test_predict_" + std::to_string(::getpid()));
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
    // Only the exact model's parameters, with chord absorption by default.
    EXPECT_EQ(f.attr_string("/prediction", "absorption"), "chord");
    for (const char* other : {"k_g", "w_c", "roots", "longitudinal", "quadrature_order", "beta_long", "alpha"})
      EXPECT_FALSE(f.has_attr("/prediction", other)) << other;
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
  rc = std::system((bin + " predict " + cfg + " --model exact --set k_g=5 -o " + bad + " 2>/dev/null").c_str());
  EXPECT_EQ(WEXITSTATUS(rc), 2);
  EXPECT_FALSE(fs::exists(bad));
  rc = std::system((bin + " predict " + cfg + " --model nosuch -o " + bad + " 2>/dev/null").c_str());
  EXPECT_EQ(WEXITSTATUS(rc), 2);
  EXPECT_FALSE(fs::exists(bad));
  fs::remove_all(dir);
}
