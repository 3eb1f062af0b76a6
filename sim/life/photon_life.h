#pragma once
// A photon's life (SPEC sections 3-5), written once for its number type T
// (sim/simd/lanes.h): enter the fiber at an impact parameter, meet the boundary,
// reflect or refract about a normal drawn by the roughness model, run straight
// segments inside, until it leaves, is truncated or (a model's choice) lost.
//
// T = double traces one photon: sim/life/tracer.cpp runs step() until the photon
// is done, the readable reference. T = xsimd::batch<double> traces a SIMD
// vector of photons, and T = Pair<Batch> (sim/simd/lane_pair.h) two of them:
// sim/life/batch_tracer.cpp keeps a pool of photons in lanes, runs step() on each
// Pair of vectors of lanes, refills the lanes whose photon is done.
// A photon draws the same random numbers in the same order either way (every
// draw is masked to the lanes that make it), so both give the same path up to
// the last bits of the vectorised log/sin/cos (tests/sim/test_batch_tracer.cpp).
//
// Branches that depend on the photon are masks: code says what each lane's
// photon does next. The path does not depend on the colour channel, so the
// life returns the total internal path length and the scorer turns it into a
// Beer-Lambert weight per channel; `weight` is the model's throughput factor
// (1 unless a roughness model's event_weight says otherwise).
#include <algorithm>
#include <type_traits>

#include "sim/life/ellipse_cross_section.h"
#include "sim/life/interface_event.h"
#include "sim/life/medulla.h"
#include "sim/roughness/roughness_model.h"
#include "sim/run/settings.h"

namespace fiberlab::sim::life {

// Russian roulette with expected-value scoring of exits (SPEC section 5;
// docs/PHYSICS.md "Estimator"): right after an interface event, a photon
// still in the fiber whose throughput weight w is below the threshold
// survives with probability w / (the weight it then carries), else its path
// ends (fate Ended). The expectation of its weight is w either way, so every
// tally is unbiased; the weight created and destroyed is booked, absorbed
// along the path so far, in the signed ledger term `roulette`, whose
// expectation is 0. Two regimes, by the photon's segments p at the event:
// - p <= 1 (the first event and the TT point): below kRouletteBelow, carrying
//   kRouletteWeight. After TT a smooth fiber leaves w ~ F ~ 0.05 > 0.03, so
//   nearly every photon goes on to score TRT: TRT's error is what these
//   weights buy.
// - p >= kRouletteLateFrom (from the TRT point on): below 1, carrying 1, that
//   is a photon goes on with probability w and then weight 1, as often as an
//   analog photon would; without it every photon whose F stays high (light-
//   guided paths) would be followed at a small weight to max_segments.
// Of the settings measured with bench/figure_of_merit.py on cases b, c and
// ggx ((0.03, 0.3), (0.05, 0.05), (0.1, 0.1), (0.2, 0.2), (1, 1) at every p;
// (0.03, 0.3), (0.05, 0.05), (0.1, 0.1) with the late regime), this one gave
// the TRT lobe the most error per second on b and c (docs/PHYSICS.md
// "Estimator").
inline constexpr double kRouletteBelow = 0.03;
inline constexpr double kRouletteWeight = 0.3;
inline constexpr double kRouletteLateFrom = 2.0;  // segments
static_assert(kRouletteWeight >= kRouletteBelow && kRouletteWeight <= 1.0,
              "a survivor must not play again at once, nor carry more than a photon starts with");

// What a photon does next.
// kEnded: ended by Russian roulette (expected-value scoring only).
enum LaneCode : int { kAtBoundary = 0, kExited = 1, kTruncated = 2, kTravel = 3, kLost = 4, kEnded = 5 };

// The fixed parts of one configuration.
struct LifeConfig {
  explicit LifeConfig(const Settings& s)
      : ellipse(s.fiber.eccentricity), eta(s.fiber.eta), cos_tilt(std::cos(s.fiber.scale_tilt)),
        sin_tilt(std::sin(s.fiber.scale_tilt)), max_segments(s.max_segments),
        max_events(s.max_events_per_point), medulla(medulla_config(s)),
        expected_value(s.estimator == Estimator::ExpectedValue) {
    for (int p = 0; p < kExitNormalsLobes; ++p) {
      exit_normals[p] = expected_value ? s.exit_normals_for(p) : 1;
      most_exit_normals = std::max(most_exit_normals, exit_normals[p]);
    }
  }
  EllipseCrossSection ellipse;
  double eta;
  double cos_tilt, sin_tilt;  // cuticle tilt towards the root (SPEC section 2)
  int max_segments, max_events;
  MedullaConfig medulla;  // not present: a plain fiber (sim/life/medulla.h)

  static MedullaConfig medulla_config(const Settings& s) {
    if (!s.fiber.medulla) return {};
    const Medulla& m = *s.fiber.medulla;
    const EllipseCrossSection e(s.fiber.eccentricity);
    return {e.r_v(), e.r_w(), m.radius, m.sigma_s, m.g, s.fiber.eta, m.eta, s.max_segments};
  }
  bool expected_value;  // expected-value scoring of exits, with Russian roulette (kRouletteBelow)
  // Settings::exit_normals by lobe p (the last for every larger p), and the
  // largest (1: no exit splitting; sim/life/exit_splitting.h).
  static constexpr int kExitNormalsLobes = static_cast<int>(kMaxExitNormalsEntries);
  int exit_normals[kExitNormalsLobes];
  int most_exit_normals = 1;
};

// The exit a photon scored at its last interface event by expected value
// (weight 0: none), before its next segment: where and how it left; and the
// weight Russian roulette created (> 0) or destroyed (< 0) right after that
// event (0: none), at the same path length. Not part of the photon's lasting state
// (the batched tracer hands it over after each step and does not keep it).
template <class T>
struct ScoredExit {
  T weight;       // throughput before absorption: weight times the leaving probability
  Vec3Of<T> d;    // the leaving direction
  T path;         // internal path length so far
  T segments;     // the lobe index p
  T medulla_path;  // 3D path length inside the medulla so far
  T scatters;      // scattering events in the medulla so far
  T roulette;      // signed weight of this step's Russian roulette, before absorption
  // The event, for exit splitting (sim/life/exit_splitting.h; set only when
  // it splits): 1 where an interface event acted this step (it splits
  // whether or not its own leaving branch left), the photon's direction and
  // throughput weight before it, the boundary point and its side (1 inside).
  T acted;
  Vec3Of<T> d_in;
  T weight_in;
  T px, py, inside;
  // 1 where the event is the photon's first (outside, at its entry point,
  // no event there before), whose split also draws the entry point.
  T first;
};

template <class T, class Light>
struct PhotonState {
  T px, py;        // boundary point (v, w)
  Vec3Of<T> d;     // direction
  T inside;        // 1 inside the fiber, 0 outside
  T path;          // internal 3D path length
  T segments;      // internal straight segments: the lobe index p
  T events_here;   // interface events at the current boundary point
  T tries;         // candidate normals drawn for the pending event
  T weight;        // throughput factor of the roughness model
  T code;          // LaneCode
  LaneRandom<T> rng;
  Light light;
  LossRecord<T> losses;  // weight removed by the model's event weights
  T medulla_path;        // 3D path length inside the medulla (sim/life/medulla.h)
  T scatters;            // scattering events in the medulla
  ScoredExit<T> scored;  // expected-value scoring: this step's exit (set only then)
};

// Photons arriving along d at the entry points (pv, pw), with their streams.
template <class Light, class T>
PhotonState<T, Light> start_photon(const T& pv, const T& pw, const Vec3Of<T>& d,
                                   const LaneRandom<T>& rng) {
  const T zero(0.0);
  return {pv, pw, d, zero, zero, zero, zero, zero, T(1.0), T(double(kAtBoundary)), rng, Light(d), {},
          zero, zero, {zero, d, zero, zero, zero, zero, zero, zero, d, zero, zero, zero, zero, zero}};
}
template <class Light>
PhotonState<double, Light> start_photon(const Point2& p, const Vec3& d,
                                        const LaneRandom<double>& rng) {
  return start_photon<Light, double>(p.x(), p.y(), Vec3Of<double>(d), rng);
}

template <class Model, class T>
concept HasEventWeight = requires(const Model& m, const EventGeometry<T>& e, const MaskOf<T>& a,
                                  LaneRandom<T>& r) {
  { m.event_weight(e, a, r) } -> std::same_as<EventWeight<T>>;
};

// Expected-value scoring (SPEC section 5) where r.scored: the leaving
// branch is the photon's scored exit, with the weight times its probability
// (times its own masking factor: G1 weights both branches), and the photon
// goes on along the other branch with the weight times one minus it.
template <class T, class Model, class Light>
void score_leaving_branch(const Model& model, PhotonState<T, Light>& s, const EventResult<T>& r,
                          const BoundaryFrame<T>& frame, const Vec3Of<T>& m,
                          const MaskOf<T>& inside, bool splits) {
  T exit_weight = select(r.scored, s.weight * r.p_leave, T(0.0));
  if constexpr (HasEventWeight<Model, T>) {
    // The leaving branch refracts when the photon is inside.
    const EventWeight<T> w =
        model.event_weight(EventGeometry<T>{s.d, r.leave_direction, m, frame, inside}, r.scored, s.rng);
    s.losses.add(r.scored & (w.factor < T(1.0)), exit_weight * (T(1.0) - w.factor), s.path);
    exit_weight = select(r.scored, select(w.lost, T(0.0), exit_weight * w.factor), T(0.0));
  }
  s.scored.weight = exit_weight;
  if (splits) {  // the event, for exit splitting (LifeConfig::most_exit_normals > 1)
    s.scored.d_in = s.d;
    s.scored.weight_in = s.weight;
    s.scored.px = s.px;
    s.scored.py = s.py;
    s.scored.inside = ones<T>(inside);
  }
  s.scored.d = r.leave_direction;
  s.scored.path = s.path;
  s.scored.segments = s.segments;
  s.scored.medulla_path = s.medulla_path;
  s.scored.scatters = s.scatters;
  s.weight = select(r.scored, s.weight * (T(1.0) - r.p_leave), s.weight);
}

// The macro normals at a boundary point of untilted outward normal n0 as a
// photon on the side `inside` sees them: the tilted normal
// n_s = cos(alpha) n0 - sin(alpha) u, facing the photon.
template <class T>
BoundaryFrame<T> boundary_frame(const LifeConfig& c, const Vec3Of<T>& n0, const MaskOf<T>& inside) {
  const T side = select(inside, T(-1.0), T(1.0));
  const T sin_n = side * T(-c.sin_tilt);
  return {Vec3Of<T>(sin_n, side * T(c.cos_tilt) * n0.y, side * T(c.cos_tilt) * n0.z), side * n0, sin_n,
          T(c.cos_tilt)};
}

// The refractive indices across the boundary for a photon on the side `inside`.
template <class T>
InterfaceIndex<T> interface_index(const LifeConfig& c, const MaskOf<T>& inside) {
  return {select(inside, T(1.0 / c.eta), T(c.eta)), select(inside, T(c.eta), T(1.0 / c.eta))};
}

// One interface event for the photons in `live` at a boundary point (SPEC
// section 3): draw the normal, reflect or refract, apply the consistency
// rule (the new direction must leave the boundary on the photon's new side,
// judged with the untilted normal; otherwise another event at the same
// point, at most max_events). kExpectedValue: c.expected_value, fixed at
// compile time so that the analog life carries no code of the other.
template <bool kExpectedValue, class T, class Model, class Light>
MaskOf<T> interface_event(const LifeConfig& c, const Model& model, PhotonState<T, Light>& s,
                     const MaskOf<T>& live, LifeCounts<T>& counts, int rounds) {
  const MaskOf<T> inside = s.inside != T(0.0);
  const Vec3Of<T> n0 = c.ellipse.normal_at(s.px, s.py);
  const BoundaryFrame<T> frame = boundary_frame(c, n0, inside);
  const FacetDraw<T> f = model.draw_normal(s.d, frame, live, s.rng, s.tries, counts, rounds);
  const MaskOf<T> act = f.ready;  // never failed too (sim/roughness/roughness_model.h)
  const InterfaceIndex<T> index = interface_index<T>(c, inside);
  EventResult<T> r;
  if constexpr (kExpectedValue) {
    r = s.light.interact(s.d, f.m, index, act, s.rng, ExitScoring<T>{act, inside, n0});
    score_leaving_branch(model, s, r, frame, f.m, inside, c.most_exit_normals > 1);
    if (c.most_exit_normals > 1) {
      s.scored.acted = ones<T>(act);
      s.scored.first = ones<T>(act & !inside & (s.segments == T(0.0)) & (s.events_here == T(0.0)));
    }
  } else {
    r = s.light.interact(s.d, f.m, index, act, s.rng);
  }
  const Vec3Of<T> d = select(act, r.direction, s.d);
  MaskOf<T> lost(false);
  if constexpr (HasEventWeight<Model, T>) {
    const EventWeight<T> w =
        model.event_weight(EventGeometry<T>{s.d, d, f.m, frame, r.refracted}, act, s.rng);
    s.losses.add(act & (w.factor < T(1.0)), s.weight * (T(1.0) - w.factor), s.path);
    lost = act & w.lost;
    s.weight = select(act, select(lost, T(0.0), s.weight * w.factor), s.weight);
  }
  const MaskOf<T> flip = act & r.refracted;
  // != is exclusive or on masks (not ^: xsimd 8.1's ^ of AVX-512 masks is an
  // or; sim/simd/lanes.h).
  const MaskOf<T> now_inside = flip != inside;
  const T dn = d.dot(n0);
  const MaskOf<T> consistent = (now_inside & (dn < T(0.0))) | ((!now_inside) & (dn > T(0.0)));
  T code = select(consistent, select(now_inside, T(kTravel), T(kExited)), T(kAtBoundary));
  code = select(f.failed, T(kTruncated), code);
  code = select(lost, T(kLost), code);
  code = select(act | f.failed, code, s.code);
  s.d = d;
  s.inside = ones<T>(now_inside);
  s.events_here = s.events_here + ones<T>(act);
  // Still undecided after max_events events at this point: truncated.
  const MaskOf<T> stuck = act & !consistent & !lost & (s.events_here >= T(c.max_events));
  s.code = select(stuck, T(kTruncated), code);
  counts.events = counts.events + ones<T>(act);
  return act;
}

// One internal segment for the photons about to cross the fiber (SPEC
// sections 2 and 4). A photon that did not leave at the boundary ending its
// last allowed segment is truncated (SPEC section 5), and so is one running
// exactly along the axis (guided for ever). Always inline: out of line, GCC
// passes the state through memory (bench/bench_sim.cpp shows the cost).
template <class T, class Light>
[[gnu::always_inline]] inline void travel(const LifeConfig& c, PhotonState<T, Light>& s,
                                          const MaskOf<T>& live) {
  const MaskOf<T> at_limit = live & (s.code == T(kTravel)) & (s.segments >= T(c.max_segments));
  s.code = select(at_limit, T(kTruncated), s.code);
  const MaskOf<T> go = live & (s.code == T(kTravel));
  if (!any(go)) return;
  MaskOf<T> along_axis(false);
  const T t = select(go, c.ellipse.distance_to_boundary(s.px, s.py, s.d.y, s.d.z, along_axis),
                     T(0.0));
  const MaskOf<T> moved = go & !along_axis;
  T pv = s.px, pw = s.py;
  c.ellipse.advance(pv, pw, s.d.y, s.d.z, t);
  T cortex = t;
  const MaskOf<T> stuck = c.medulla.present ? cross_medulla(c.medulla, s, moved, cortex, pv, pw)
                                            : MaskOf<T>(false);
  s.px = select(moved, pv, s.px);
  s.py = select(moved, pw, s.py);
  s.path = s.path + cortex;
  s.segments = s.segments + ones<T>(moved);
  s.events_here = select(moved, T(0.0), s.events_here);
  s.code = select(moved, T(kAtBoundary), select(go & along_axis, T(kTruncated), s.code));
  s.code = select(stuck, T(kTruncated), s.code);
}

// Russian roulette (kRouletteBelow) for the photons in `live` whose
// interface event acted this step (`acted`), just after it and before their
// next segment (a photon that ends here travels no further); gives back the
// lanes that go on. Only a photon still in the fiber's life plays (kTravel,
// or kAtBoundary: another event at the same point). A lane whose normal is
// still being drawn (the batched tracer draws over several steps; the
// reference tracer in one) does not play, so both tracers play at the same
// events. Draws from a lane's stream only where it plays, so the analog
// estimator's streams are untouched.
template <class T, class Light>
MaskOf<T> russian_roulette(PhotonState<T, Light>& s, const MaskOf<T>& live, const MaskOf<T>& acted) {
  s.scored.roulette = T(0.0);
  const MaskOf<T> going_on = (s.code == T(kTravel)) | (s.code == T(kAtBoundary));
  const MaskOf<T> late = s.segments >= T(kRouletteLateFrom);
  const T carry = select(late, T(1.0), T(kRouletteWeight));
  const T below = select(late, T(1.0), T(kRouletteBelow));
  const MaskOf<T> play = acted & going_on & (s.weight < below) & (s.weight > T(0.0));
  if (!any(play)) return live;
  const T u = s.rng.uniform(play);
  const MaskOf<T> survive = play & (u * carry < s.weight);
  const MaskOf<T> ended = play & !survive;
  s.scored.roulette =
      select(survive, carry - s.weight, select(ended, -s.weight, T(0.0)));
  s.weight = select(survive, carry, select(ended, T(0.0), s.weight));
  s.code = select(ended, T(kEnded), s.code);
  return live & !ended;
}

// One step of the life for the photons in `live`, all at a boundary point:
// an interface event, then the next segment for those that go on inside.
// kExpectedValue must be c.expected_value (the tracers choose the
// instantiation once per run).
template <bool kExpectedValue, class T, class Model, class Light>
void step(const LifeConfig& c, const Model& model, PhotonState<T, Light>& s,
          const MaskOf<T>& live, LifeCounts<T>& counts, int rounds) {
  if constexpr (kExpectedValue) {
    const MaskOf<T> acted = interface_event<true>(c, model, s, live, counts, rounds);
    travel(c, s, russian_roulette(s, live, acted));
  } else {
    interface_event<false>(c, model, s, live, counts, rounds);
    travel(c, s, live);
  }
}

}  // namespace fiberlab::sim::life
