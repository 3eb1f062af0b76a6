#pragma once
// The configuration of `fiberlab atlas` (configs/atlas.yaml is the shipped
// example; configs/README.md describes every key): which physical fibers to
// simulate and which models to fit to each.
//
//   photons: 200000       # per fiber and incident direction
//   seed: 1               # every fiber's simulation uses it
//   eta: 1.55
//   tally: {n_theta: 36, n_phi: 72, lobes: 4}
//   sweep:                # every combination of these lists is one fiber
//     roughness:          # each entry a simulator roughness block (SPEC s3 / s11)
//       - {model: gaussian, beta_long: 5}
//       - {model: ggx, alpha: 0.1}       # microfacet (SPEC s3)
//     absorption:         # each entry {sigma_a: X or [X, ...]} or {melanin: {eumelanin, pheomelanin}}
//       - {sigma_a: 0.0}
//     scale_tilt: [0, 3]  # degrees
//     eccentricity: [1.0]
//     medulla: [none, {radius: 0.5, sigma_s: 8}]  # optional: fur (docs/FUR.md); none: no medulla
//     theta_i: [0, 30, 60]  # degrees: the incident directions of every fiber
//   models: all           # or a list of registered model names and variants:
//   #  [deon2011, {name: chiang2016_pbrt, model: chiang2016, parameters: {mp: pbrt_v4}}]
//   model_parameters:     # optional: fixed (not fitted) parameters per model
//     huang2022: {quadrature_points: 262144}
//   fit: {max_iterations: 20, lobes: [R, TT, TRT]}   # lobes: optional, default every lobe;
//   # any name of the atlas's lobe axis (atlas_lobe_names: `scattered` too
//   # when a fiber has a medulla; a fiber fits those of them it has)
//   # per_lobe: optional (false): after the joint fit, each lobe of fit.lobes
//   # fitted alone from the joint fit's values (compare/atlas.h)
//
// A variant is a registered model under its own name (letters, digits, _
// and -; unique among the entries) with its own fixed parameters (the rules
// of model_parameters below, applied after the model's model_parameters if
// any): the same model can appear several times side by side. Entries are
// ordered by the registry's order of their models; a model's variants follow
// it, in the config's order. The name is what the tables, file and report
// show.
//
// model_parameters: for a model of `models`, keys of its own parameter table
// (`fiberlab models`) that the fit does not move (a free key is refused: the
// fit starts from the fiber's physical value), in command-line units. They
// are applied on top of the model's physical defaults for each fiber
// (ModelInfo::from_fiber, compare/models.h params_for), so they hold for the
// "before" comparison, the fit and the "after" one; each value is checked by
// the table's own parser when the config is read.
//
// fit.model_parameters: the same rules, for settings applied on top of the
// above only while fitting (a cheaper quadrature, say): the "before" and
// "after fit" comparisons, chi-squares and everything judged use the
// parameters without them. A model's settings hold for its variants too. A
// free key is refused here as well: the fit moves it.
//
// Each fiber is checked by the simulator's own config parser (the entry is
// written as a simulator config and parsed back), so a roughness model the
// simulator learns later is accepted here without change. Everything is
// checked before anything runs: a bad value is one line naming the file, the
// entry and what is allowed (fiberlab::Error, exit status 2).
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "sim/run/settings.h"

namespace fiberlab::compare {

// One physical fiber of the sweep.
struct AtlasFiber {
  sim::Settings settings;       // what the simulator traces (every theta_i)
  std::string label;            // "gaussian 5 deg, sigma_a=0, tilt 3, e 1"
  std::string roughness_model;  // the simulator's roughness model name
  double roughness = 0.0;       // its size: beta_long (deg) or alpha; 0 for smooth
  std::string roughness_unit;   // "deg" (beta) or "" (alpha)
  int roughness_index = 0, absorption_index = 0, tilt_index = 0, eccentricity_index = 0;
  int medulla_index = 0;        // sweep.medulla's entry (0 without the list)
  std::string absorption_label; // "sigma_a=0.2" or "melanin 0.8/0.1"
};

struct AtlasConfig {
  std::string path, yaml;       // the file and its text (stored in the output)
  std::vector<AtlasFiber> fibers;
  // Entry names: registered models and variants, in registry order.
  std::vector<std::string> models;
  // Variant name -> the registered model it runs (registered names absent).
  std::map<std::string, std::string> variant_of;
  // Entry name -> its fixed settings "KEY=VALUE" (model_parameters; for a
  // variant, its model's then its own), checked.
  std::map<std::string, std::vector<std::string>> model_parameters;
  // Entry name -> its fit-only settings "KEY=VALUE" (fit.model_parameters of
  // its model), applied on top of model_parameters while fitting; checked.
  std::map<std::string, std::vector<std::string>> fit_model_parameters;
  int max_iterations = 20;
  // fit.lobes: the lobes the fit judges and fits, indices into
  // atlas_lobe_names() (empty: every lobe).
  std::vector<int> fit_lobes;
  // fit.per_lobe: after the joint fit, each of those lobes fitted alone.
  bool per_lobe = false;
  std::vector<double> theta_i;  // radians
};

// The lobe names of a fiber's result (sim::ResultFile::lobe_names() of its
// run): the tally's lobes by p, `scattered` last with a medulla (docs/FUR.md).
std::vector<std::string> fiber_lobe_names(const AtlasFiber& fiber);
// The atlas's lobe axis, what its file's `lobe_names` holds: the longest of
// any fiber's (every fiber shares the tally, so it is a medullated fiber's
// when there is one), named as that fiber names them.
std::vector<std::string> atlas_lobe_names(const std::vector<AtlasFiber>& fibers);

// The registered model an entry of config.models runs (itself unless a variant).
const std::string& registered_model(const AtlasConfig& config, const std::string& entry);

// Parses and checks the atlas config text; `origin` names it in errors.
AtlasConfig parse_atlas_config(const std::string& yaml_text, const std::string& origin);
AtlasConfig load_atlas_config(const std::string& path);

// `fiberlab atlas --photons N`: N photons per fiber and incident direction
// for every fiber, read by sim::parse_integer_flag's rules (1 to 10^12, the
// config's own range). Throws fiberlab::Error naming the flag.
void override_photons(AtlasConfig& config, const std::string& flag_text);

}  // namespace fiberlab::compare
