// Every model parameter has a meaningful range in its table, checked in one
// place (analytic::check_params, called by make_model) whatever way the value
// came: --set text, a simulation's fiber, a fit, an atlas config.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "analytic/deon2011.h"
#include "analytic/marschner2003.h"
#include "analytic/model_registry.h"
#include "analytic/smooth_cylinder.h"
#include "common/error.h"
#include "common/physical_limits.h"
#include "common/units.h"
#include "tests/error_text.h"

namespace fiberlab::analytic {
namespace {

TEST(ParamRanges, EveryParameterHasARangeAndItsDefaultIsInIt) {
  for (const ModelInfo& m : registered_models()) {
    const ModelParameters p = default_params(m.name);
    for (const ParamSpec& s : m.params) {
      ASSERT_TRUE(s.in_range) << m.name << " " << s.key;
      EXPECT_TRUE(s.in_range(p)) << m.name << " " << s.key << " default " << s.default_value;
    }
    EXPECT_NO_THROW(check_params(m.name, m.params, p)) << m.name;
  }
}

TEST(ParamRanges, ValuesSetWithoutTextAreCheckedBeforeAModelIsBuilt) {
  // d'Eon's beta_long = 1e300 degrees once gave energy 0 silently.
  ModelParameters p = default_params("deon2011");
  p.as<Deon2011Params>().beta_long = {deg_to_rad(1e300)};
  const std::string e = error_of([&] { make_model("deon2011", p); });
  EXPECT_NE(e.find("model deon2011: beta_long = 1e+300 is out of range; allowed: a comma list of degrees in [0, 90]"),
            std::string::npos)
      << e;
  // The fiber's eta, from a result, at and beyond the simulator's bound.
  ModelParameters q = default_params("exact");
  q.as<ExactParams>().eta = kMaxEta;
  EXPECT_NO_THROW(check_params("exact", model_info("exact").params, q));
  q.as<ExactParams>().eta = std::nextafter(kMaxEta, INFINITY);
  EXPECT_NE(error_of([&] { make_model("exact", q); }).find("eta = 1e+09 is out of range; allowed: a number in (1, 1e9]"),
            std::string::npos);
  q.as<ExactParams>().eta = NAN;
  EXPECT_NE(error_of([&] { make_model("exact", q); }).find("eta = nan is out of range"), std::string::npos);
  ModelParameters r = default_params("marschner2003");
  r.as<Marschner2003Params>().eccentricity = 1e-310;
  EXPECT_NE(error_of([&] { make_model("marschner2003", r); }).find("eccentricity"), std::string::npos);
  r = default_params("marschner2003");
  r.as<Marschner2003Params>().k_g = 1e300;
  EXPECT_NE(error_of([&] { make_model("marschner2003", r); }).find("k_g = 1e+300 is out of range"), std::string::npos);
}

TEST(ParamRanges, SetTextAtAndBeyondTheBounds) {
  ModelParameters p = default_params("deon2011");
  EXPECT_NO_THROW(apply_setting("deon2011", p, "beta_long=90"));
  EXPECT_THROW(apply_setting("deon2011", p, "beta_long=90.000001"), Error);
  EXPECT_NO_THROW(apply_setting("deon2011", p, "alpha=-180,180"));
  EXPECT_THROW(apply_setting("deon2011", p, "alpha=-180.5"), Error);
  EXPECT_NO_THROW(apply_setting("deon2011", p, "eta=1e9"));
  EXPECT_THROW(apply_setting("deon2011", p, "eta=1.000001e9"), Error);
  ModelParameters m = default_params("huang2022");
  EXPECT_NO_THROW(apply_setting("huang2022", m, "eccentricity=2.2250738585072014e-308"));
  EXPECT_THROW(apply_setting("huang2022", m, "eccentricity=2.2e-308"), Error);
}

// SPEC s7's shift rule (R -2a, TT +a, TRT +4a, p >= 3: 0) at the ends of the
// simulator's tilt range (-45, 45) (SPEC s11), where a fit of scale_tilt can
// go: every model with per-lobe shifts accepts the shifts it gives.
TEST(ParamRanges, ShiftsOfEverySimulatorTiltAreInRange) {
  for (const char* model : {"deon2011", "marschner2003"})
    for (double a : {deg_to_rad(-45.0 + 1e-6), deg_to_rad(45.0 - 1e-6)}) {  // the structs hold radians
      ModelParameters p = default_params(model);
      apply_setting(model, p, "beta_long=5");  // marschner2003 needs a width > 0
      const std::vector<double> shifts{-2.0 * a, a, 4.0 * a, 0.0};
      if (p.holds<Deon2011Params>()) p.as<Deon2011Params>().alpha = shifts;
      else p.as<Marschner2003Params>().alpha = shifts;
      EXPECT_NO_THROW(make_model(model, p)) << model << " at tilt " << a;
    }
}

TEST(ParamRanges, ARepeatedSetKeyIsRefused) {
  ModelParameters p = default_params("deon2011");
  EXPECT_NO_THROW(apply_settings("deon2011", p, {"beta_long=2", "beta_azim=3"}));
  const std::string e = error_of([&] { apply_settings("deon2011", p, {"beta_long=2", " beta_long =3"}); });
  EXPECT_NE(e.find("--set  beta_long =3: beta_long is already set by --set beta_long=2"), std::string::npos) << e;
}

}  // namespace
}  // namespace fiberlab::analytic
