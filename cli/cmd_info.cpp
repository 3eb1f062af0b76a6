// `fiberlab info FILE.h5`: what a fiberlab file of any kind holds
// (docs/FILE_FORMAT.md); the description: app/info.h.
#include <fmt/core.h>

#include <memory>

#include "app/info.h"
#include "cli/commands.h"
#include "cli/summary_table.h"

namespace fiberlab::cli {

void add_info_command(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand("info", "Describe a fiberlab file: a result (parameters, photons, lobe "
                                               "energies), run checkpoint, prediction, report data, atlas or "
                                               "atlas checkpoint");
  cmd->add_option("file", *path, "A fiberlab HDF5 file (.h5)")->required();
  cmd->callback([path] {
    const app::FileDescription d = app::describe_file(*path);
    fmt::print("{}", d.text);
    if (d.result) print_summary(stdout, *d.result);
  });
}

}  // namespace fiberlab::cli
