#include "sim/life/tracer.h"

namespace fiberlab::sim {

Tracer::Tracer(const Settings& s)
    : config_(s), roughness_(make_roughness(s)), polarization_(s.polarization) {}

PhotonOutcome Tracer::trace(const Vec3& wi, double h, PhotonRandom& rng,
                            TracerCounters* counters) const {
  return std::visit(
      [&](const auto& model) {
        return polarization_ == Polarization::Stokes
                   ? trace_with<life::StokesLight<double>>(model, wi, h, rng, counters)
                   : trace_with<life::ScalarLight<double>>(model, wi, h, rng, counters);
      },
      roughness_);
}

template <class Light, class Model>
PhotonOutcome Tracer::trace_with(const Model& model, const Vec3& wi, double h, PhotonRandom& rng,
                                 TracerCounters* counters) const {
  const Vec3 d = -wi;
  auto s = life::start_photon<Light>(config_.ellipse.entry_point(d, h), d, rng.core());
  life::LifeCounts<double> counts;
  std::vector<ScoredExitOutcome> scored;
  while (s.code == static_cast<double>(life::kAtBoundary)) {
    if (config_.expected_value)
      step<true>(config_, model, s, true, counts, kMaxNormalTries);
    else
      step<false>(config_, model, s, true, counts, kMaxNormalTries);
    const bool own_row = s.scored.weight > 0.0 || s.scored.roulette != 0.0;
    if (config_.expected_value && (own_row || s.scored.acted != 0.0)) {
      const int p = static_cast<int>(s.scored.segments);
      Vec3 d = s.scored.d.to_vec3();
      if (s.scored.weight > 0.0) {
        PhotonRandom blur = scored_exit_stream(s.rng.word(0), s.rng.word(1), s.rng.word(2), s.rng.word(3));
        d = exit_direction_of(model, d, p, blur);
      }
      // Exit splitting: the extra normals' exits first (the first carrying
      // what the split created), the event's own (with the roulette term)
      // last, as the batched tracer hands them over.
      life::SplitExits<1> split;
      life::split_scored_exits(config_, model, s.scored, s.rng, split);
      for (int k = 1; k < split.n; ++k) {
        const double roulette = k == 1 ? split.created[0] : 0.0;
        if (split.weight[k][0] > 0.0 || roulette != 0.0)
          scored.push_back({Vec3(split.dx[k][0], split.dy[k][0], split.dz[k][0]), p, s.scored.path,
                            split.weight[k][0], s.scored.medulla_path, s.scored.scatters > 0.0, roulette});
      }
      if (own_row)
        scored.push_back({d, p, s.scored.path, split.weight[0][0], s.scored.medulla_path,
                          s.scored.scatters > 0.0, s.scored.roulette});
    }
  }
  rng.core() = s.rng;
  if (counters) counters->add(counts);
  PhotonOutcome out = finished_outcome(model, static_cast<int>(s.code), s.d.to_vec3(),
                                       static_cast<int>(s.segments), s.path, s.weight, rng);
  out.losses = std::move(s.losses.list);
  out.scored = std::move(scored);
  out.medulla_path = s.medulla_path;
  out.scattered = s.scatters > 0.0;
  if (out.fate == PhotonFate::Exited) {
    out.theta = inclination(out.direction);
    out.phi = azimuth(out.direction);
  }
  return out;
}

}  // namespace fiberlab::sim
