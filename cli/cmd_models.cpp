// `fiberlab models [--markdown]`: every analytic model and its parameters
// (key, meaning, unit, default, allowed values, what a simulation sets),
// from the models' own tables (analytic/model_registry.h).
#include <fmt/core.h>

#include <memory>

#include "analytic/model_registry.h"
#include "cli/commands.h"

namespace fiberlab::cli {

void add_models_command(CLI::App& app) {
  auto markdown = std::make_shared<bool>(false);
  CLI::App* cmd = app.add_subcommand(
      "models", "List the analytic models and each one's --set keys (meaning, unit, default, range)");
  cmd->add_flag("--markdown", *markdown, "Markdown tables (docs/MODELS.md)");
  cmd->callback([markdown] { fmt::print("{}", analytic::models_listing(*markdown)); });
}

}  // namespace fiberlab::cli
