// The YAML configuration contract (SPEC section 11): parsing, defaults,
// units, the melanin formula, the to_yaml round trip and the error messages.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/units.h"
#include "sim/run/settings.h"

namespace fiberlab::sim {
namespace {

namespace fs = std::filesystem;

Settings parse(const std::string& yaml) { return parse_settings_yaml(yaml, "configs/x.yaml"); }

// The message of the Error that parsing `yaml` throws ("" when none is thrown).
std::string error_of(const std::string& yaml) {
  try {
    parse(yaml);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// An error message: one line, starting with the origin, containing every piece.
void expect_error(const std::string& yaml, const std::vector<std::string>& pieces) {
  SCOPED_TRACE("config:\n" + yaml);
  const std::string message = error_of(yaml);
  ASSERT_FALSE(message.empty()) << "no error";
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_EQ(message.rfind("configs/x.yaml: ", 0), 0u) << message;
  for (const auto& piece : pieces) EXPECT_NE(message.find(piece), std::string::npos)
      << "'" << piece << "' not in: " << message;
}

// ---------------------------------------------------------------- shipped configs

// The run configs (atlas*.yaml are `fiberlab atlas` sweeps, tested in
// tests/compare/test_atlas_config.cpp).
std::vector<fs::path> shipped_configs() {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(fs::path(FIBERLAB_SOURCE_DIR) / "configs"))
    if (entry.path().extension() == ".yaml" && !entry.path().filename().string().starts_with("atlas"))
      files.push_back(entry.path());
  return files;
}

TEST(Settings, EveryShippedConfigParsesAndRoundTrips) {
  const auto files = shipped_configs();
  EXPECT_GE(files.size(), 4u);
  for (const auto& file : files) {
    SCOPED_TRACE(file.string());
    Settings s;
    ASSERT_NO_THROW(s = load_settings(file.string()));
    EXPECT_EQ(parse_settings_yaml(to_yaml(s), file.string()), s);
  }
}

TEST(Settings, ShippedConfigsHaveTheDocumentedContents) {
  const fs::path dir = fs::path(FIBERLAB_SOURCE_DIR) / "configs";
  const Settings quick = load_settings((dir / "quickstart.yaml").string());
  EXPECT_EQ(quick.output, "quickstart.h5");
  EXPECT_EQ(quick.photons, 1000000u);
  EXPECT_DOUBLE_EQ(quick.source.theta_i.at(0), deg_to_rad(30.0));
  EXPECT_TRUE(std::holds_alternative<roughness::Gaussian>(quick.fiber.roughness));
  EXPECT_TRUE(quick.fiber.eumelanin.has_value());

  const Settings sweep = load_settings((dir / "white_fiber_sweep.yaml").string());
  EXPECT_EQ(sweep.source.theta_i.size(), 18u);
  EXPECT_EQ(sweep.fiber.sigma_a, std::vector<double>{0.0});

  const Settings glints = load_settings((dir / "elliptical_glints.yaml").string());
  EXPECT_DOUBLE_EQ(glints.fiber.eccentricity, 0.85);
  EXPECT_EQ(glints.source.phi_i.size(), 4u);

  const Settings smooth = load_settings((dir / "smooth_circle.yaml").string());
  EXPECT_TRUE(std::holds_alternative<roughness::Smooth>(smooth.fiber.roughness));
  EXPECT_EQ(smooth.fiber.scale_tilt, 0.0);
  EXPECT_EQ(smooth.incidences().size(), 3u);
}

// ---------------------------------------------------------------- values

TEST(Settings, EmptyMappingGivesTheDefaults) {
  const Settings s = parse("{}\n");
  EXPECT_EQ(s.photons, 1000000u);
  EXPECT_EQ(s.seed, 1u);
  EXPECT_EQ(s.output, "x.h5");  // the config file's stem
  EXPECT_EQ(s.fiber.eta, 1.55);
  EXPECT_EQ(s.fiber.eccentricity, 1.0);
  EXPECT_EQ(s.fiber.scale_tilt, 0.0);
  EXPECT_EQ(s.fiber.sigma_a, (std::vector<double>{0.0, 0.0, 0.0}));
  EXPECT_FALSE(s.fiber.eumelanin.has_value());
  EXPECT_EQ(std::get<roughness::Gaussian>(s.fiber.roughness).beta_long, 0.0);
  EXPECT_EQ(std::get<roughness::Gaussian>(s.fiber.roughness).beta_azim, 0.0);
  EXPECT_EQ(s.source.theta_i, std::vector<double>{0.0});
  EXPECT_FALSE(s.source.phi_i_uniform);
  EXPECT_EQ(s.source.phi_i, std::vector<double>{0.0});
  EXPECT_EQ(s.tally.n_theta, 90);
  EXPECT_EQ(s.tally.n_phi, 180);
  EXPECT_EQ(s.tally.theta_bins, ThetaBinning::Uniform);
  EXPECT_EQ(s.tally.lobes, 4);
  EXPECT_EQ(s.max_segments, 1000);
  EXPECT_EQ(s.max_events_per_point, 1000);
  EXPECT_EQ(s.polarization, Polarization::Scalar);
  EXPECT_EQ(parse("fiber:\nroughness: {}\n"), s);  // empty sections too
}

TEST(Settings, AnglesAreDegreesInTheFileAndRadiansInSettings) {
  const Settings s = parse(
      "fiber: {scale_tilt: 3}\n"
      "roughness: {model: gaussian, beta_long: 5, beta_azim: 10}\n"
      "source: {theta_i: [30, -45], phi_i: 90}\n");
  EXPECT_DOUBLE_EQ(s.fiber.scale_tilt, 3.0 * kPi / 180.0);
  EXPECT_DOUBLE_EQ(std::get<roughness::Gaussian>(s.fiber.roughness).beta_long, 5.0 * kPi / 180.0);
  EXPECT_DOUBLE_EQ(std::get<roughness::Gaussian>(s.fiber.roughness).beta_azim, 10.0 * kPi / 180.0);
  EXPECT_DOUBLE_EQ(s.source.theta_i.at(0), kPi / 6.0);
  EXPECT_DOUBLE_EQ(s.source.theta_i.at(1), -kPi / 4.0);
  EXPECT_DOUBLE_EQ(s.source.phi_i.at(0), kPi / 2.0);
}

TEST(Settings, EveryFieldIsRead) {
  const Settings s = parse(
      "photons: 1e6\nseed: 0\noutput: out/a.h5\n"
      "fiber: {eta: 1.6, eccentricity: 0.5, sigma_a: [0.1, 0.2]}\n"
      "roughness: {model: exit_blur, beta_long: [4, 8, 12]}\n"
      "tally: {n_theta: 45, n_phi: 90, theta_bins: equal_area, lobes: 6}\n"
      "max_segments: 50\nmax_events_per_point: 20\npolarization: stokes\n");
  EXPECT_EQ(s.photons, 1000000u);  // 1e6 is exactly integral: accepted
  EXPECT_EQ(s.seed, 0u);
  EXPECT_EQ(s.output, "out/a.h5");
  EXPECT_EQ(s.fiber.eta, 1.6);
  EXPECT_EQ(s.fiber.eccentricity, 0.5);
  EXPECT_EQ(s.fiber.sigma_a, (std::vector<double>{0.1, 0.2}));
  const auto& blur = std::get<roughness::ExitBlur>(s.fiber.roughness);
  ASSERT_EQ(blur.beta_long.size(), 3u);
  EXPECT_EQ(blur.beta_azim, blur.beta_long);  // beta_azim defaults to beta_long
  EXPECT_DOUBLE_EQ(roughness::ExitBlur::for_lobe(blur.beta_long, 7), deg_to_rad(12.0));
  EXPECT_EQ(s.tally.n_theta, 45);
  EXPECT_EQ(s.tally.n_phi, 90);
  EXPECT_EQ(s.tally.theta_bins, ThetaBinning::EqualArea);
  EXPECT_EQ(s.tally.lobes, 6);
  EXPECT_EQ(s.max_segments, 50);
  EXPECT_EQ(s.max_events_per_point, 20);
  EXPECT_EQ(s.polarization, Polarization::Stokes);
}

TEST(Settings, SingleSigmaAIsOneChannel) {
  EXPECT_EQ(parse("fiber: {sigma_a: 0.5}\n").fiber.sigma_a, std::vector<double>{0.5});
}

TEST(Settings, ThetaRangeIncludesTheEnd) {
  const Settings s = parse("source: {theta_i: {from: 0, to: 85, step: 5}}\n");
  ASSERT_EQ(s.source.theta_i.size(), 18u);
  for (std::size_t i = 0; i < 18; ++i)
    EXPECT_DOUBLE_EQ(s.source.theta_i[i], deg_to_rad(5.0 * static_cast<double>(i)));

  // `to` is included within 1e-9 of a step, never exceeded.
  const Settings tenths = parse("source: {theta_i: {from: -1, to: 1, step: 0.1}}\n");
  ASSERT_EQ(tenths.source.theta_i.size(), 21u);
  EXPECT_EQ(tenths.source.theta_i.back(), deg_to_rad(1.0));
  EXPECT_EQ(tenths.source.theta_i[13], deg_to_rad(0.3));
  EXPECT_EQ(parse("source: {theta_i: {from: 0, to: 9.99, step: 5}}\n").source.theta_i.size(), 2u);
  EXPECT_EQ(parse("source: {theta_i: {from: 10, to: 10, step: 5}}\n").source.theta_i.size(), 1u);
}

TEST(Settings, IncidencesAreThetaMajor) {
  const Settings s = parse("fiber: {eccentricity: 0.8}\nsource: {theta_i: [10, 20], phi_i: [0, 30, 60]}\n");
  const auto inc = s.incidences();
  ASSERT_EQ(inc.size(), 6u);
  EXPECT_DOUBLE_EQ(inc[0].theta_i, deg_to_rad(10.0));
  EXPECT_DOUBLE_EQ(inc[2].phi_i, deg_to_rad(60.0));
  EXPECT_DOUBLE_EQ(inc[3].theta_i, deg_to_rad(20.0));
  EXPECT_DOUBLE_EQ(inc[3].phi_i, 0.0);

  const auto uniform = parse("source: {theta_i: [10, 20], phi_i: uniform}\n");
  EXPECT_TRUE(uniform.source.phi_i_uniform);
  const auto inc_u = uniform.incidences();
  ASSERT_EQ(inc_u.size(), 2u);
  EXPECT_TRUE(std::isnan(inc_u[0].phi_i));
  EXPECT_TRUE(std::isnan(inc_u[1].phi_i));
}

TEST(Settings, MelaninFollowsDEon2011Section6_1) {
  // d'Eon et al. 2011, section 6.1:
  // sigma_a = ce * (0.419, 0.697, 1.37) + cp * (0.187, 0.4, 1.05)
  const auto eu = sigma_a_from_melanin(1.0, 0.0);
  ASSERT_EQ(eu.size(), 3u);
  EXPECT_DOUBLE_EQ(eu[0], 0.419);
  EXPECT_DOUBLE_EQ(eu[1], 0.697);
  EXPECT_DOUBLE_EQ(eu[2], 1.37);
  const auto pheo = sigma_a_from_melanin(0.0, 1.0);
  EXPECT_DOUBLE_EQ(pheo[0], 0.187);
  EXPECT_DOUBLE_EQ(pheo[1], 0.4);
  EXPECT_DOUBLE_EQ(pheo[2], 1.05);

  const Settings s = parse("fiber: {melanin: {eumelanin: 0.8, pheomelanin: 0.1}}\n");
  ASSERT_EQ(s.fiber.sigma_a.size(), 3u);
  EXPECT_NEAR(s.fiber.sigma_a[0], 0.8 * 0.419 + 0.1 * 0.187, 1e-12);  // 0.3539
  EXPECT_NEAR(s.fiber.sigma_a[1], 0.8 * 0.697 + 0.1 * 0.4, 1e-12);    // 0.5976
  EXPECT_NEAR(s.fiber.sigma_a[2], 0.8 * 1.37 + 0.1 * 1.05, 1e-12);    // 1.201
  EXPECT_EQ(s.fiber.eumelanin, 0.8);
  EXPECT_EQ(s.fiber.pheomelanin, 0.1);

  // One concentration omitted counts as 0.
  const Settings eu_only = parse("fiber: {melanin: {eumelanin: 2}}\n");
  EXPECT_EQ(eu_only.fiber.pheomelanin, 0.0);
  EXPECT_EQ(eu_only.fiber.sigma_a, sigma_a_from_melanin(2.0, 0.0));
}

TEST(Settings, ToStrings) {
  EXPECT_EQ(roughness::name(roughness::Smooth{}), "smooth");
  EXPECT_EQ(roughness::name(roughness::Gaussian{}), "gaussian");
  EXPECT_EQ(roughness::name(roughness::ExitBlur{}), "exit_blur");
  EXPECT_EQ(to_string(Polarization::Scalar), "scalar");
  EXPECT_EQ(to_string(Polarization::Stokes), "stokes");
}

// ---------------------------------------------------------------- round trip

TEST(Settings, ToYamlRoundTripsExactly) {
  Settings s;
  s.photons = 123456789;
  s.seed = 18446744073709551615u;
  s.output = "dir with space/\"quoted\": x.h5";
  s.fiber.eta = 1.5500000000000003;
  s.fiber.eccentricity = 0.85;
  s.fiber.scale_tilt = 0.0523598775598;  // radians that are no "round" degree value
  s.fiber.sigma_a = {0.1, 1e-7, 3.0, 12345.678};
  s.fiber.roughness = roughness::ExitBlur{{{0.01, 0.2, 0.3}, {0.4}}};
  s.source.theta_i = {-1.2, 0.0, 0.123456789, 1.5};
  s.source.phi_i = {-3.0, 0.5, 2.0};
  s.tally = {45, 91, ThetaBinning::EqualArea, 5};
  s.max_segments = 77;
  s.max_events_per_point = 12;
  s.polarization = Polarization::Stokes;
  EXPECT_EQ(parse(to_yaml(s)), s) << to_yaml(s);

  Settings m = parse("fiber: {melanin: {eumelanin: 0.3, pheomelanin: 0.7}}\nsource: {phi_i: uniform}\n");
  const std::string text = to_yaml(m);
  EXPECT_NE(text.find("melanin"), std::string::npos);
  EXPECT_EQ(parse(text), m) << text;

  // Every key is explicit and angles are degrees.
  const std::string q = to_yaml(parse("fiber: {scale_tilt: 3}\nsource: {theta_i: 30}\n"));
  for (const char* key : {"photons:", "seed:", "output:", "eta:", "eccentricity:", "scale_tilt: 3",
                          "sigma_a:", "model:", "beta_long:", "beta_azim:", "theta_i: [30]",
                          "phi_i:", "n_theta:", "n_phi:", "theta_bins:", "lobes:",
                          "max_segments:", "polarization:"})
    EXPECT_NE(q.find(key), std::string::npos) << key << " not in\n" << q;
}

// ---------------------------------------------------------------- errors

TEST(SettingsErrors, TheExampleMessage) {
  EXPECT_EQ(error_of("fiber:\n  eta: 0.9\n"),
            "configs/x.yaml: fiber.eta = 0.9 is out of range (must be in (1, 1e9]: beyond 1e9 the Fresnel transmittance is lost in rounding)");
}

TEST(SettingsErrors, MalformedYamlReportsLineAndColumn) {
  expect_error("fiber:\n  eta: 1.5\n   bad: [1, 2\n", {"malformed YAML", "line 3", "column"});
  expect_error("source: {theta_i: [1, 2}\n", {"malformed YAML", "line 1"});
  expect_error("seed: 1\n---\nseed: 2\n", {"2 YAML documents", "exactly one"});
}

TEST(SettingsErrors, WrongTypes) {
  expect_error("fiber: {eta: abc}\n", {"fiber.eta", "abc", "not a number", "must be in (1, 1e9]"});
  expect_error("fiber: {eta: \"1.5\"}\n", {"fiber.eta", "not a number", "must be in (1, 1e9]"});
  expect_error("fiber: {eta: [1, 2]}\n", {"fiber.eta", "is a list", "must be in (1, 1e9]"});
  expect_error("fiber: {eta: }\n", {"fiber.eta", "no value", "must be in (1, 1e9]"});
  expect_error("fiber: 3\n", {"fiber = 3", "mapping", "eta, eccentricity"});
  expect_error("photons: 1.5\n", {"photons = 1.5", "not an integer", "integer >= 1"});
  expect_error("photons: lots\n", {"photons = lots", "not an integer", "integer >= 1"});
  expect_error("seed: [1]\n", {"seed", "is a list", "integer >= 0"});
  expect_error("tally: {n_theta: 90.5}\n", {"tally.n_theta = 90.5", "not an integer", ">= 1"});
  expect_error("roughness: {model: rough}\n",
               {"roughness.model = rough", "smooth, gaussian, exit_blur"});
  expect_error("polarization: Stokes\n", {"polarization = Stokes", "scalar, stokes"});
  expect_error("tally: {theta_bins: log}\n", {"tally.theta_bins = log", "uniform, equal_area"});
  expect_error("source: {phi_i: random}\n", {"source.phi_i = random", "uniform"});
  expect_error("output: [a, b]\n", {"output", "is a list", "non-empty"});
  expect_error("- 1\n- 2\n", {"the config is a list", "photons"});
}

TEST(SettingsErrors, OutOfRange) {
  expect_error("photons: 0\n", {"photons = 0", "out of range", "integer >= 1"});
  expect_error("photons: -5\n", {"photons = -5", "out of range", "integer >= 1"});
  expect_error("seed: -1\n", {"seed = -1", "out of range", "integer >= 0"});
  expect_error("output: ''\n", {"output", "empty", "non-empty"});
  expect_error("fiber: {eta: 1}\n", {"fiber.eta = 1", "out of range", "(1, 1e9]"});
  expect_error("fiber: {eta: .nan}\n", {"fiber.eta", "finite", "(1, 1e9]"});
  expect_error("fiber: {eccentricity: 0}\n", {"fiber.eccentricity = 0", "[2.2250738585072014e-308, 1]"});
  expect_error("fiber: {eccentricity: 1.2}\n", {"fiber.eccentricity = 1.2", "[2.2250738585072014e-308, 1]"});
  expect_error("fiber: {scale_tilt: -45}\n", {"fiber.scale_tilt = -45", "(-45, 45)"});
  expect_error("fiber: {sigma_a: [0.1, -0.2]}\n", {"fiber.sigma_a[1] = -0.2", ">= 0"});
  expect_error("fiber: {sigma_a: [0.1, .inf]}\n", {"fiber.sigma_a[1]", "finite", ">= 0"});
  expect_error("fiber: {sigma_a: []}\n", {"fiber.sigma_a", "empty", "1 to 64"});
  std::string many = "fiber: {sigma_a: [0";
  for (int i = 0; i < 64; ++i) many += ", 0";
  expect_error(many + "]}\n", {"fiber.sigma_a", "65 channels", "1 to 64"});
  expect_error("fiber: {melanin: {eumelanin: -1}}\n",
               {"fiber.melanin.eumelanin = -1", ">= 0"});
  expect_error("fiber: {melanin: {}}\n", {"fiber.melanin", "eumelanin and/or pheomelanin"});
  expect_error("roughness: {beta_long: -1}\n", {"roughness.beta_long = -1", "[0, 90]"});
  expect_error("roughness: {beta_long: 91}\n", {"roughness.beta_long = 91", "[0, 90]"});
  expect_error("roughness: {model: exit_blur, beta_azim: [5, 95]}\n",
               {"roughness.beta_azim[1] = 95", "[0, 90]"});
  expect_error("roughness: {model: exit_blur, beta_long: []}\n",
               {"roughness.beta_long", "empty", "[0, 90]"});
  expect_error("source: {theta_i: 90}\n", {"source.theta_i = 90", "(-90, 90)"});
  expect_error("source: {theta_i: [0, -90]}\n", {"source.theta_i[1] = -90", "(-90, 90)"});
  expect_error("source: {theta_i: []}\n", {"source.theta_i", "empty", "(-90, 90)"});
  expect_error("source: {phi_i: .inf}\n", {"source.phi_i", "finite"});
  expect_error("tally: {n_phi: 0}\n", {"tally.n_phi = 0", ">= 1"});
  expect_error("tally: {lobes: 0}\n", {"tally.lobes = 0", ">= 1"});
  expect_error("tally: {n_theta: 3000000000}\n", {"tally.n_theta = 3000000000", "[1, 2147483647]"});
  expect_error("max_segments: 0\n", {"max_segments = 0", ">= 1"});
  expect_error("seed: 18446744073709551616\n", {"seed", "out of range"});
}

TEST(SettingsErrors, ThetaRange) {
  expect_error("source: {theta_i: {from: 0, to: 90, step: 5}}\n",
               {"source.theta_i.to = 90", "(-90, 90)"});
  expect_error("source: {theta_i: {from: 0, to: 80, step: 0}}\n",
               {"source.theta_i.step = 0", "> 0"});
  expect_error("source: {theta_i: {from: 10, to: 0, step: 1}}\n",
               {"source.theta_i.to = 0", ">= from"});
  expect_error("source: {theta_i: {from: 0, to: 80}}\n", {"source.theta_i.step", "missing"});
  expect_error("source: {theta_i: {from: 0, to: 80, step: 5, by: 2}}\n",
               {"unknown key source.theta_i.by", "from, to, step"});
  expect_error("source: {theta_i: {from: -89, to: 89, step: 1e-9}}\n",
               {"source.theta_i", "at most 100000"});
}

TEST(SettingsErrors, UnknownKeys) {
  expect_error("phtons: 10\n", {"unknown key phtons", "did you mean photons", "polarization"});
  expect_error("fiber: {etaa: 1.5}\n", {"unknown key fiber.etaa", "eta, eccentricity"});
  expect_error("tally: {n_thetas: 5}\n", {"unknown key tally.n_thetas", "n_theta"});
  expect_error("fiber: {melanin: {eumelanine: 1}}\n",
               {"unknown key fiber.melanin.eumelanine", "eumelanin, pheomelanin"});
  expect_error("seed: 1\nseed: 2\n", {"duplicate key seed"});
}

TEST(SettingsErrors, SigmaAAndMelaninTogether) {
  expect_error("fiber: {sigma_a: 0.1, melanin: {eumelanin: 1}}\n",
               {"fiber.sigma_a", "fiber.melanin", "both"});
}

TEST(SettingsErrors, ListBetaForGaussian) {
  expect_error("roughness: {model: gaussian, beta_long: [5, 10]}\n",
               {"roughness.beta_long = [5, 10]", "list", "[0, 90]", "exit_blur"});
  expect_error("roughness: {beta_azim: [5]}\n", {"roughness.beta_azim", "list", "exit_blur"});
  // exit_blur takes a list indexed by p.
  EXPECT_EQ(std::get<roughness::ExitBlur>(parse("roughness: {model: exit_blur, beta_long: [5, 10]}\n").fiber.roughness).beta_long.size(),
            2u);
}

TEST(SettingsErrors, TallyTooLarge) {
  expect_error("tally: {n_theta: 9000, n_phi: 18000}\n",
               {"tally.n_theta = 9000", "tally.n_phi = 18000", "8 GiB"});
  // 20 incidences x 4 lobes x 900 x 1800 x 3 channels x 16 B = 6.2 GB: allowed.
  EXPECT_NO_THROW(parse("source: {theta_i: {from: 0, to: 76, step: 4}}\n"
                        "tally: {n_theta: 900, n_phi: 1800}\n"));
}

TEST(SettingsErrors, MissingFile) {
  const std::string path = "/nonexistent/fiberlab/none.yaml";
  try {
    load_settings(path);
    FAIL() << "no error";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind(path + ": cannot read config file: ", 0), 0u) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos);
  }
}

TEST(SettingsErrors, LoadSettingsNamesTheFile) {
  const fs::path file = fs::temp_directory_path() /
                     ("fiberlab_test_settings_" + std::to_string(::getpid()) + ".yaml");
  {
    std::FILE* f = std::fopen(file.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs("fiber:\n  eta: 0.9\n", f);
    std::fclose(f);
  }
  try {
    load_settings(file.string());
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), file.string() + ": fiber.eta = 0.9 is out of range (must be in (1, 1e9]: beyond 1e9 the Fresnel transmittance is lost in rounding)");
  }
  fs::remove(file);
}

}  // namespace
}  // namespace fiberlab::sim
