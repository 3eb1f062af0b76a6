#pragma once
// Fit-only settings: "KEY=VALUE" parameters of a model put on top of the
// judged parameters while a fit runs, and only then. huang2022's
// quadrature_points is the case in point: the fit's many predictions at a
// cheap quadrature, every verdict at the accurate one. The atlas's
// fit.model_parameters, `compare --fit-set` and fiberlab.fit(fit_settings=)
// all go through here.
#include <string>
#include <vector>

#include "analytic/model_parameters.h"
#include "compare/fit.h"

namespace fiberlab::compare {

// Refuses (fiberlab::Error naming `flag`, e.g. "--fit-set") a setting that
// is not KEY=VALUE of the model's table, a key given twice, a key one of
// the fit `keys` moves (the fit would move it), a key the simulated fiber or
// its tally sets (eta, sigma_a, eccentricity, lobes, tilt, ...: the fit
// would then fit another fiber), or a value the key's parser refuses.
void check_fit_settings(const std::string& model_name, const std::vector<std::string>& settings,
                        const std::vector<std::string>& keys, const std::string& flag);

// `judged` with `settings` on top (checked ones), through the model's own
// checks: the parameters a fit starts from.
analytic::ModelParameters with_fit_settings(const std::string& model_name, const analytic::ModelParameters& judged,
                                            const std::vector<std::string>& settings);

// fit.params made the judged parameters at the fit's values: `judged`
// (per-lobe lists written out as lobe_fit_start() does) with each fitted key
// set. What every verdict after a fit with fit-only settings uses.
void put_onto_judged(const std::string& model_name, const analytic::ModelParameters& judged, FitResult& fit);

}  // namespace fiberlab::compare
