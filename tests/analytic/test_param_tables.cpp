// Each model owns its parameter struct, and its table's entries bind to that
// struct's fields (analytic/model_params.h, model_registry.h): a key of one
// model is refused for another, a table applied to another model's struct is
// refused, and every entry round-trips set -> show -> attribute on its own
// field only.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "analytic/chiang2016.h"
#include "analytic/deon2011.h"
#include "analytic/huang2022.h"
#include "analytic/marschner2003.h"
#include "analytic/model_registry.h"
#include "analytic/smooth_cylinder.h"
#include "common/error.h"
#include "common/units.h"

namespace fiberlab::analytic {
namespace {

// A value of each numeric key other than every model's default (the
// defaults: `fiberlab models`), in command-line units.
const std::map<std::string, std::string> kOtherValue{
    {"eta", "1.6"},          {"sigma_a", "0.1,0.2,0.3,0.4"}, {"beta_long", "5,10"},
    {"beta_azim", "7"},      {"alpha", "-6,3,12"},           {"eccentricity", "0.85"},
    {"k_g", "0.4"},          {"w_c", "12"},                  {"delta_eta", "0.2"},
    {"delta_h_m", "0.25"},   {"lobes", "5"},                 {"quadrature_order", "50"},
    {"max_order", "30"},     {"beta_m", "0.4"},              {"beta_n", "0.6"},
    {"roughness", "0.2"},    {"tilt", "3"},                  {"lobe_scale", "1,0.5,2"},
    {"quadrature_points", "65536"},  {"quadrature_photons", "1e+06"}};

// chiang2016's `alpha` is one tilt, not a list.
std::string other_value(const std::string& model, const ParamSpec& spec) {
  if (model == "chiang2016" && spec.key == "alpha") return "3";
  if (spec.unit == "choice") {  // the first choice that is not the default
    std::istringstream in(spec.allowed);
    std::string choice, bar;
    while (in >> choice) {
      if (choice != spec.default_value) return choice;
      in >> bar;
    }
  }
  return kOtherValue.at(spec.key);
}

std::vector<double> numbers_of(const std::string& text) {
  std::vector<double> out;
  std::istringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) out.push_back(std::strtod(item.c_str(), nullptr));
  return out;
}

// Every key of model A that model B does not have is refused by B with a
// one-line error naming the key and B's keys (and nothing of B's changes).
TEST(ParamTables, AKeyOfOneModelIsRefusedByAnother) {
  int refused = 0;
  for (const ModelInfo& a : registered_models())
    for (const ModelInfo& b : registered_models()) {
      if (a.name == b.name) continue;
      for (const ParamSpec& spec : a.params) {
        if (find_param(b.params, spec.key)) continue;
        ModelParameters p = default_params(b.name);
        const std::string before = describe_params(b.name, p);
        try {
          apply_setting(b.name, p, spec.key + "=" + other_value(a.name, spec));
          ADD_FAILURE() << b.name << " took " << a.name << "'s " << spec.key;
        } catch (const Error& e) {
          const std::string msg = e.what();
          EXPECT_NE(msg.find("model " + b.name + " has no parameter '" + spec.key + "'"), std::string::npos) << msg;
          EXPECT_NE(msg.find(key_list(b.params)), std::string::npos) << msg;
          EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
        }
        EXPECT_EQ(describe_params(b.name, p), before);
        ++refused;
      }
    }
  EXPECT_GT(refused, 40);  // e.g. deon2011's n_theta_d for each of the other four
}

// One model's parameters given to another model's table or factory are
// refused (fiberlab::Error naming the model), even for a key both have.
// Mutation tried and caught: apply_setting() without the registry's check.
TEST(ParamTables, AnotherModelsParametersAreRefused) {
  for (const ModelInfo& a : registered_models())
    for (const ModelInfo& b : registered_models()) {
      if (a.name == b.name) continue;
      ModelParameters p = default_params(a.name);
      for (const auto& call : std::vector<std::function<void()>>{
               [&] { apply_setting(b.name, p, "eta=1.5"); }, [&] { make_model(b.name, p); },
               [&] { describe_params(b.name, p); }, [&] { param_attributes(b.name, p); },
               [&] { theta_r_shifts(b.name, p); }}) {
        try {
          call();
          ADD_FAILURE() << b.name << " took " << a.name << "'s parameters";
        } catch (const Error& e) {
          EXPECT_NE(std::string(e.what()).find("model " + b.name + ": the parameters given are not"),
                    std::string::npos)
              << e.what();
        }
      }
    }
  EXPECT_THROW(make_model("exact", ModelParameters()), Error);
  EXPECT_THROW(ModelParameters(Deon2011Params{}).as<ExactParams>(), std::logic_error);
}

// Every entry of every table: --set text -> show gives the text back, the
// file attribute holds the value in file units (radians for "deg"), and no
// other entry of the table moves (each key has its own field of the struct)
// but a preset's documented keys (huang2022's form=cycles_eval sets masking,
// flux and residual to Cycles' eval()'s).
// Mutation tried and caught: deon2011's beta_azim bound to the beta_long field.
TEST(ParamTables, EveryEntryRoundTripsOnItsOwnField) {
  const std::set<std::string> preset_moves = {"huang2022 form masking", "huang2022 form flux",
                                              "huang2022 form residual"};
  for (const ModelInfo& m : registered_models()) {
    for (const ParamSpec& spec : m.params) {
      ModelParameters p = default_params(m.name);
      std::map<std::string, std::string> before;
      for (const ParamSpec& s : m.params) before[s.key] = s.show(p);
      const std::string value = other_value(m.name, spec);
      ASSERT_NE(value, spec.show(p)) << m.name << " " << spec.key << ": the test value is the default";
      apply_setting(m.name, p, spec.key + "=" + value);
      EXPECT_EQ(spec.show(p), value) << m.name << " " << spec.key;
      for (const ParamSpec& s : m.params) {
        if (s.key != spec.key && !preset_moves.count(m.name + " " + spec.key + " " + s.key)) {
          EXPECT_EQ(s.show(p), before[s.key]) << m.name << ": " << spec.key << " moved " << s.key;
        }
      }
      const ParamAttribute a = spec.attribute(p);
      EXPECT_EQ(a.name, spec.key);
      if (spec.unit == "choice") {
        EXPECT_TRUE(a.is_text);
        EXPECT_EQ(a.text, value) << m.name << " " << spec.key;
      } else {
        EXPECT_FALSE(a.is_text);
        std::vector<double> expect = numbers_of(value);
        if (spec.unit == "deg")
          for (double& x : expect) x = deg_to_rad(x);
        ASSERT_EQ(a.numbers.size(), expect.size()) << m.name << " " << spec.key;
        for (std::size_t i = 0; i < expect.size(); ++i) EXPECT_DOUBLE_EQ(a.numbers[i], expect[i]) << spec.key;
      }
      EXPECT_NO_THROW(check_params(m.name, m.params, p)) << m.name << " " << spec.key;
    }
  }
}

// The table writes the model's own struct: the fields the models read.
TEST(ParamTables, SettingsLandInTheModelsStruct) {
  ModelParameters d = default_params("deon2011");
  apply_settings("deon2011", d, {"beta_azim=7", "r_fresnel=per_h", "n_theta_d=specular", "max_order=30"});
  const Deon2011Params& dp = d.as<Deon2011Params>();
  EXPECT_DOUBLE_EQ(dp.beta_azim.at(0), deg_to_rad(7.0));
  EXPECT_FALSE(dp.r_half_angle_fresnel);
  EXPECT_TRUE(dp.specular_theta_d);
  EXPECT_EQ(dp.max_order, 30);
  ModelParameters c = default_params("chiang2016");
  apply_settings("chiang2016", c, {"alpha=3", "mp=pbrt_v4"});
  EXPECT_DOUBLE_EQ(c.as<Chiang2016Params>().alpha, deg_to_rad(3.0));
  EXPECT_EQ(c.as<Chiang2016Params>().mp, Chiang2016Mp::PbrtV4);
  ModelParameters h = default_params("huang2022");
  apply_settings("huang2022", h, {"masking=none", "residual=cycles_eval", "flux=macro", "quadrature_points=65536"});
  const Huang2022Params& hp = h.as<Huang2022Params>();
  EXPECT_EQ(hp.masking, HuangMasking::None);
  EXPECT_EQ(hp.residual, HuangResidual::CyclesEval);
  EXPECT_FALSE(hp.mesonormal_flux);
  EXPECT_EQ(hp.quadrature_points, 65536);
  ModelParameters k = default_params("marschner2003");
  apply_settings("marschner2003", k, {"roots=exact", "longitudinal=two_theta_h", "w_c=12"});
  EXPECT_TRUE(k.as<Marschner2003Params>().exact_roots);
  EXPECT_TRUE(k.as<Marschner2003Params>().two_theta_h);
  EXPECT_DOUBLE_EQ(k.as<Marschner2003Params>().w_c, deg_to_rad(12.0));
}

// The theta_r shift per lobe each model applies (the comparison's alpha):
// SPEC s7's rule R -2a, TT +a, TRT +4a, p >= 3: 0 for the models with one
// tilt a (chiang2016.h: lobe centres -theta_i - 2a, + a, + 4a), the per-lobe
// list itself for the models that take shifts, none for the exact model.
TEST(ParamTables, ThetaRShiftsFollowTheModelsOwnTilt) {
  const std::vector<double> rule{deg_to_rad(-6.0), deg_to_rad(3.0), deg_to_rad(12.0), 0.0};
  for (const auto& [model, key] : std::vector<std::pair<std::string, std::string>>{
           {"chiang2016", "alpha=3"}, {"huang2022", "tilt=3"}, {"deon2011", "alpha=-6,3,12,0"},
           {"marschner2003", "alpha=-6,3,12,0"}}) {
    ModelParameters p = default_params(model);
    apply_setting(model, p, key);
    const std::vector<double> shifts = theta_r_shifts(model, p);
    ASSERT_EQ(shifts.size(), rule.size()) << model;
    for (std::size_t i = 0; i < rule.size(); ++i) EXPECT_NEAR(shifts[i], rule[i], 1e-15) << model << " " << i;
  }
  EXPECT_EQ(theta_r_shifts("exact", default_params("exact")), std::vector<double>{0.0});
}

}  // namespace
}  // namespace fiberlab::analytic
