#pragma once
// Every rank of a run must trace the same physics into the same tally shape
// with the same photon counts and seed: a rank started with another config or
// flags (`mpirun -np 1 fiberlab run A.yaml : -np 1 fiberlab run B.yaml`) would
// add its sums into a file labelled with rank 0's config, or desynchronise
// the ranks' collective calls (a hang, or tallies of another size summed into
// rank 0's). The ranks compare, before any photon, one digest per field of
// what decides the output; the lowest differing rank is named with its first
// differing field.
#include <optional>
#include <string>

#include "sim/run/process_group.h"
#include "sim/run/settings.h"
#include "sim/run/simulation.h"

namespace fiberlab::sim {

// What the ranks must agree on, one "key: value" line per field: the
// resolved config (to_yaml: physics, roughness, source, tally shape, photons,
// seed, output), --target-error (it decides when the ranks stop and flush),
// and, for a resumed run, the checkpoint's progress. (--threads, --quiet and
// --checkpoint-every may differ: they change no bit of the output, and rank
// 0 alone decides when to checkpoint.)
std::string run_agreement_text(const Settings& settings, double target_error,
                               const RunProgress* resumed);

// nullopt when every rank's text is rank 0's. Otherwise, on every rank, one
// line: "rank 1 was started with another config or flags than rank 0:
// fiber.eta = 1.6 on rank 1, 1.55 on rank 0 (...)". Collective: every rank calls it.
std::optional<std::string> ranks_disagree(const ProcessGroup& group, const std::string& text);

}  // namespace fiberlab::sim
