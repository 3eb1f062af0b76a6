#pragma once
// Each subcommand of `fiberlab` lives in its own cmd_*.cpp and registers itself
// on the application here. A command's callback throws fiberlab::Error on bad
// input (exit status 2) and returns its own exit status through `exit_code`.
#include <CLI/CLI.hpp>

namespace fiberlab::cli {

inline int exit_code = 0;

void add_run_command(CLI::App& app);
void add_info_command(CLI::App& app);
void add_merge_command(CLI::App& app);
void add_predict_command(CLI::App& app);
void add_compare_command(CLI::App& app);
void add_energy_command(CLI::App& app);
void add_models_command(CLI::App& app);
void add_atlas_command(CLI::App& app);

}  // namespace fiberlab::cli
