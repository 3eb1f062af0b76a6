#include "app/predict.h"

#include "analytic/model_registry.h"

namespace fiberlab::app {

ChosenModel choose_model(const sim::Settings& s, const compare::ModelSpec& spec,
                         const std::vector<std::string>& sets) {
  ChosenModel chosen;
  chosen.spec = spec;
  chosen.params = compare::params_for(s, spec, sets, &chosen.fiber_notes);
  chosen.model = compare::make_model(spec.name, chosen.params);
  return chosen;
}

compare::PredictionFile predict(const sim::Settings& s, const ChosenModel& chosen) {
  compare::PredictionFile pred;
  pred.model = chosen.spec.name;
  pred.grid = BinGrid::make(s.tally.n_theta, s.tally.n_phi, s.tally.theta_bins);
  pred.lobes = analytic::predicted_lobes(chosen.spec.name, chosen.params);
  pred.channels = analytic::predicted_channels(chosen.spec.name, chosen.params);
  // A fiber with a medulla: its histogram's last lobe is `scattered`, which
  // no model predicts (docs/FUR.md); a zero lobe follows the model's, as
  // compare::predict_config pads a result's, so the file's lobe axis is the result's.
  const int model_lobes = pred.lobes;
  pred.scattered = s.fiber.medulla.has_value();
  if (pred.scattered) ++pred.lobes;
  for (const sim::Settings::Incidence& inc : s.incidences()) {
    pred.theta_i.push_back(inc.theta_i);
    pred.phi_i.push_back(inc.phi_i);
    std::vector<double> p = compare::predict_bins(*chosen.model, pred.grid, inc.theta_i, inc.phi_i, model_lobes,
                                                  pred.channels, s.fiber.eccentricity != 1.0);
    p.resize(pred.per_config(), 0.0);
    pred.probability.insert(pred.probability.end(), p.begin(), p.end());
  }
  return pred;
}

}  // namespace fiberlab::app
