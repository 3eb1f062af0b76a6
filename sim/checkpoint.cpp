#include "sim/checkpoint.h"

#include <fmt/core.h>

#include <cmath>

#include "common/error.h"
#include "common/file_schema.h"
#include "common/result_layout.h"
#include "common/units.h"
#include "sim/result_stream.h"

namespace fiberlab::sim {

std::string checkpoint_path(const std::string& output) {
  const std::string ext = ".h5";
  if (output.size() > ext.size() && output.ends_with(ext))
    return output.substr(0, output.size() - ext.size()) + ".checkpoint.h5";
  return output + ".checkpoint.h5";
}

ResultFile result_header(const Settings& settings, const BinGrid& grid) {
  return make_result(settings, grid, {});
}

void write_checkpoint(const std::string& path, const Simulation& sim, const RunProgress& state,
                      double target_error) {
  ResultWriter w(path, result_header(sim.settings(), sim.grid()));
  for (std::size_t k = 0; k < state.tallies.size(); ++k) w.write(k, state.tallies[k].exact());
  h5::File& f = w.file();
  f.set_attr("/", "target_error", target_error);
  f.create_group("/checkpoint");
  f.set_attr("/checkpoint", "checkpoint_version", static_cast<std::int64_t>(kCheckpointVersion));
  f.set_attr("/checkpoint", "chunk", static_cast<std::int64_t>(Simulation::kChunk));
  f.set_attr("/checkpoint", "target_batch", static_cast<std::int64_t>(Simulation::kTargetBatch));
  f.write("/checkpoint/next_photon", {state.next_photon.size()}, state.next_photon);
  std::vector<std::uint64_t> done(state.done.begin(), state.done.end());
  f.write("/checkpoint/done", {done.size()}, done);
  describe(f, "/checkpoint/next_photon", "incidence", "photons",
           "photons [0, next_photon) of each incident direction are in the sums");
  describe(f, "/checkpoint/done", "incidence", "0/1", "1 once the incident direction is finished");
  w.commit();
}

Checkpoint read_checkpoint(const std::string& path, bool with_tallies) {
  const ResultReader reader(path, /*allow_empty_directions=*/true);
  const h5::File& f = reader.file();
  if (!f.exists("/checkpoint"))
    throw Error(fmt::format("{}: not a fiberlab checkpoint (no /checkpoint group)", path));
  auto attr = [&](const char* name) -> std::int64_t {
    if (!f.has_attr("/checkpoint", name))
      throw Error(fmt::format("{}: /checkpoint@{} is missing", path, name));
    return f.attr_int("/checkpoint", name);
  };
  const std::string version = reader.header().software_version;
  if (version != FIBERLAB_VERSION || attr("checkpoint_version") != kCheckpointVersion)
    throw Error(fmt::format("{}: written by fiberlab {} (checkpoint format {}); this is fiberlab {} "
                            "(format {}): resume it with the version that wrote it",
                            path, version, attr("checkpoint_version"), FIBERLAB_VERSION,
                            kCheckpointVersion));
  if (attr("chunk") != static_cast<std::int64_t>(Simulation::kChunk) ||
      attr("target_batch") != static_cast<std::int64_t>(Simulation::kTargetBatch))
    throw Error(fmt::format("{}: written with another photon chunking: resume it with the "
                            "fiberlab build that wrote it", path));
  Checkpoint c;
  c.settings = reader.header().settings;
  c.target_error = f.attr_double("/", "target_error");
  const std::size_t K = c.settings.incidences().size();
  c.state.next_photon = f.read_uint64s("/checkpoint/next_photon");
  const std::vector<std::uint64_t> done = f.read_uint64s("/checkpoint/done");
  if (c.state.next_photon.size() != K || done.size() != K || reader.header().photons.size() != K)
    throw Error(fmt::format("{}: /checkpoint does not have one entry per incident direction", path));
  for (std::size_t k = 0; k < K; ++k) {
    const std::uint64_t next = c.state.next_photon[k];
    if (done[k] > 1 || next > c.settings.photons || reader.header().photons[k] != next ||
        (!done[k] && (next % Simulation::kChunk != 0 || next == c.settings.photons)))
      throw Error(fmt::format("{}: /checkpoint of direction {} disagrees with its sums or config",
                              path, k));
    c.state.done.push_back(static_cast<std::uint8_t>(done[k]));
  }
  if (with_tallies) {
    const TallyShape s = reader.shape();
    for (std::size_t k = 0; k < K; ++k) {
      c.state.tallies.emplace_back(s.lobes, s.n_theta, s.n_phi, s.channels);
      c.state.tallies.back().add(reader.read(k));
    }
  }
  return c;
}

std::string describe_checkpoint(const std::string& path) {
  const Checkpoint c = read_checkpoint(path, /*with_tallies=*/false);
  const ResultReader reader(path, /*allow_empty_directions=*/true);
  std::string s = fmt::format("{}: fiberlab run checkpoint of {} (software {}, created {}), seed {}\n", path,
                              c.settings.output, reader.header().software_version, reader.header().created_utc,
                              c.settings.seed);
  const std::vector<Settings::Incidence> inc = c.settings.incidences();
  for (std::size_t k = 0; k < inc.size(); ++k) {
    const std::string phi =
        std::isnan(inc[k].phi_i) ? std::string("uniform") : fmt::format("{:g} deg", rad_to_deg(inc[k].phi_i));
    s += fmt::format("theta_i {:g} deg, phi_i {}: {} of {} photons{}\n", rad_to_deg(inc[k].theta_i), phi,
                     c.state.next_photon[k], c.settings.photons, c.state.done[k] ? ", finished" : "");
  }
  return s + fmt::format("resume with: fiberlab run --resume {}\n", path);
}

void check_same_config(const Checkpoint& checkpoint, const Settings& given,
                       const std::string& checkpoint_file) {
  if (to_yaml(given) != to_yaml(checkpoint.settings))
    throw Error(fmt::format("{}: the config given differs from the one the checkpoint was "
                            "started with (resume with `fiberlab run --resume {}` alone)",
                            checkpoint_file, checkpoint_file));
}

}  // namespace fiberlab::sim
