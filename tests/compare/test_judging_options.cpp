// compare's judging options and inputs: each option
// finite and in its range, a comparison that judges no lobe accepts nothing,
// a prediction's probabilities finite and >= 0, each fitted parameter once.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "common/error.h"
#include "compare/comparison.h"
#include "compare/fit.h"
#include "compare/prediction_file.h"
#include "compare/verdict.h"
#include "tests/error_text.h"

namespace fiberlab::compare {
namespace {

TEST(JudgingOptions, RangesNamedInTheCallersSpelling) {
  const double inf = std::numeric_limits<double>::infinity(), nan = std::nan("");
  EXPECT_NO_THROW(check_options(Options{}, std::nullopt, OptionSpelling::CommandLine));
  EXPECT_NO_THROW(check_options(Options{1.0, 0.0, 0.0}, 2.0, OptionSpelling::CommandLine));
  EXPECT_NO_THROW(check_options(Options{1.0, 1.0, 0.999}, 1e-9, OptionSpelling::CommandLine));
  for (double bad : {inf, nan, 1.0, -1e-9})
    EXPECT_NE(error_of([&] { check_options(Options{30, 1e-4, bad}, std::nullopt, OptionSpelling::CommandLine); })
                  .find("--min-energy"),
              std::string::npos)
        << bad;
  for (double bad : {inf, nan, 0.0, -1.0})
    EXPECT_NE(error_of([&] { check_options(Options{}, bad, OptionSpelling::Python); }).find("max_chi2 = "),
              std::string::npos)
        << bad;
  for (double bad : {nan, -1.0, 1.5, inf})
    EXPECT_NE(error_of([&] { check_options(Options{30, bad, 1e-4}, std::nullopt, OptionSpelling::CommandLine); })
                  .find("--model-error"),
              std::string::npos)
        << bad;
  for (double bad : {nan, 0.0, inf})
    EXPECT_NE(error_of([&] { check_options(Options{bad, 1e-4, 1e-4}, std::nullopt, OptionSpelling::Python); })
                  .find("min_effective"),
              std::string::npos)
        << bad;
}

TEST(JudgingOptions, NothingJudgedIsNotAccepted) {
  LobeComparison unjudged;
  unjudged.judged = false;
  EXPECT_FALSE(judge({unjudged, unjudged}, 0.0).all_accepted);
  EXPECT_FALSE(judge({}, 0.0).all_accepted);
  LobeComparison good = unjudged;
  good.judged = true;
  good.bins.dof = 10;
  good.bins.chi2 = 10.0;  // chi2/dof = 1 <= 1 + 5 sqrt(0.2)
  const Verdict v = judge({good, unjudged}, 0.0);
  EXPECT_TRUE(v.all_accepted);
  EXPECT_EQ(v.judged, 1);
}

TEST(JudgingOptions, ProbabilitiesFiniteAndNonNegative) {
  // -1e-11: the rounding of fiberlab's own marschner2003 bins (accepted).
  const std::vector<double> ok{0.0, 0.5, 1e-300, -1e-300, -1e-11};
  EXPECT_NO_THROW(check_probabilities(ok.data(), ok.size(), "p"));
  for (double bad : {-1e-8, -0.0 - 1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    const std::vector<double> v{0.1, bad};
    const std::string e = error_of([&] { check_probabilities(v.data(), v.size(), "pred.h5: /prediction/probability"); });
    EXPECT_NE(e.find("pred.h5: /prediction/probability holds"), std::string::npos) << e;
    EXPECT_NE(e.find("at flat index 1 (probabilities must be finite and >= 0"), std::string::npos) << e;
  }
}

TEST(JudgingOptions, EachParameterFittedOnce) {
  EXPECT_NO_THROW(check_fit_keys("deon2011", {"beta_long[0]", "beta_long[1]", "alpha[2]"}));
  EXPECT_NO_THROW(check_fit_keys("deon2011", {"beta_long", "beta_azim", "scale_tilt"}));
  EXPECT_THROW(check_fit_keys("deon2011", {"beta_long[0]", "beta_long[0]"}), Error);
  EXPECT_THROW(check_fit_keys("deon2011", {"beta_long[1]", "beta_long"}), Error);
  EXPECT_THROW(check_fit_keys("deon2011", {"alpha[0]", "scale_tilt"}), Error);
  EXPECT_THROW(check_fit_keys("exact", {"eta", "eta"}), Error);
}

}  // namespace
}  // namespace fiberlab::compare
