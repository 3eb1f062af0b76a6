#pragma once
// The roughness of a fiber (SPEC section 3): one type per roughness model,
// each in its own file with its fields, its config reading and checks
// (`read`), its YAML text (`yaml`), its result-file attributes
// (`attributes`), its `fiberlab info` line (`describe`) and its short text
// for notes and errors (`text`). The tracers pick their sampler by visiting
// it (sim/roughness/roughness_models.h); the analytic models' rules read it
// with std::get_if / std::visit (analytic/physical_defaults.cpp).
//
// To add a model: its file here (a struct with kName, keys() and the members
// above) and its name in the variant below; then its sampler in
// sim/roughness/ and what the analytic rules make of it.
#include <string>
#include <variant>
#include <vector>

#include "common/config_reader.h"
#include "common/roughness/exit_blur.h"
#include "common/roughness/gaussian.h"
#include "common/roughness/masking.h"
#include "common/roughness/microfacet.h"
#include "common/roughness/smooth.h"

namespace fiberlab {

using Roughness = std::variant<roughness::Smooth, roughness::Gaussian, roughness::ExitBlur,
                               roughness::Beckmann, roughness::Ggx>;

namespace roughness {

// The `roughness:` section of a run config (an absent section: gaussian, 0).
Roughness read(const config::Reader& r, const YAML::Node& config);

// The model's name in configs and files ("ggx").
std::string name(const Roughness& g);
// The `roughness:` block of a resolved config, "roughness:\n  model: ggx\n  alpha: ...".
std::string yaml(const Roughness& g);
std::vector<Attribute> attributes(const Roughness& g);
// "ggx, alpha_long 0.3, alpha_azim 0.1, masking none" (`fiberlab info`).
std::string describe(const Roughness& g);
// "ggx alpha = [0.3, 0.1]", for notes and errors.
std::string text(const Roughness& g);
// The masking of a microfacet model; None for the others.
Masking masking(const Roughness& g);

}  // namespace roughness
}  // namespace fiberlab
