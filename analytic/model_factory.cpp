#include "analytic/model_factory.h"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include "analytic/deon2011.h"
#include "analytic/marschner2003.h"
#include "analytic/smooth_cylinder.h"
#include "common/error.h"

namespace fiberlab::analytic {

const std::vector<std::string>& model_names() {
  static const std::vector<std::string> names{"exact", "deon2011", "marschner2003"};
  return names;
}

std::unique_ptr<Model> make_model(const std::string& name, const ModelParams& params) {
  if (name == "exact") return make_smooth_cylinder(params);
  if (name == "deon2011") return make_deon2011(params);
  if (name == "marschner2003") return make_marschner2003(params);
  throw Error(fmt::format("--model {}: unknown model; allowed: {}", name,
                          fmt::join(model_names(), " | ")));
}

}  // namespace fiberlab::analytic
