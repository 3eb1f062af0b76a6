#pragma once
// `fiberlab info FILE.h5`: what a fiberlab file of any kind holds
// (docs/FILE_FORMAT.md): result, run checkpoint, prediction, report data,
// atlas, atlas checkpoint.
#include <optional>
#include <string>

#include "sim/store/result_file.h"

namespace fiberlab::app {

struct FileDescription {
  std::string text;                       // the description, line by line
  std::optional<sim::ResultFile> result;  // a result file: its lobe energies follow `text` (the run's summary table)
};

// Reads the root attribute `format` and describes the file by its kind;
// fiberlab::Error naming the file and the kinds read for any other.
FileDescription describe_file(const std::string& path);

}  // namespace fiberlab::app
