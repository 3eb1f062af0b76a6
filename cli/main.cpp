// fiberlab: Monte Carlo ground truth for light scattering by hair and fur fibers.
#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <new>

#include "cli/commands.h"
#include "common/allocator_tuning.h"
#include "common/error.h"
#include "common/h5_file.h"

int main(int argc, char** argv) {
  fiberlab::tune_allocator();
  fiberlab::h5::prepare_hdf5();
  // Named, so that usage lines say `fiberlab`, not the path it was started by.
  CLI::App app{"fiberlab " FIBERLAB_VERSION ": Monte Carlo ground truth for light scattering by single fibers",
               "fiberlab"};
  app.set_version_flag("--version", std::string(FIBERLAB_VERSION));
  app.require_subcommand(1);
  fiberlab::cli::add_run_command(app);
  fiberlab::cli::add_info_command(app);
  fiberlab::cli::add_merge_command(app);
  fiberlab::cli::add_predict_command(app);
  fiberlab::cli::add_compare_command(app);
  fiberlab::cli::add_energy_command(app);
  fiberlab::cli::add_models_command(app);
  fiberlab::cli::add_atlas_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int status = app.exit(e);
    return status == 0 ? 0 : 2;
  } catch (const fiberlab::Error& e) {
    fmt::print(stderr, "fiberlab: error: {}\n", e.what());
    if (fiberlab::h5::abandoned_a_written_file()) {  // see common/h5_file.h
      std::fflush(nullptr);
      std::_Exit(2);
    }
    return 2;
  } catch (const std::bad_alloc&) {
    fmt::print(stderr, "fiberlab: error: out of memory (lower the tally size, the incident "
                       "angles or --threads); no output written\n");
    return 2;
  } catch (const std::exception& e) {
    fmt::print(stderr, "fiberlab: internal error: {}\n", e.what());
    return 3;
  }
  return fiberlab::cli::exit_code;
}
