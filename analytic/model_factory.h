#pragma once
// A Model by name, from ModelParams.
#include <memory>
#include <string>
#include <vector>

#include "analytic/model.h"

namespace fiberlab::analytic {

// "exact" (smooth_cylinder.h), "deon2011", "marschner2003". Throws
// fiberlab::Error naming the allowed names, or the model's own parameter error.
std::unique_ptr<Model> make_model(const std::string& name, const ModelParams& params);
const std::vector<std::string>& model_names();

}  // namespace fiberlab::analytic
