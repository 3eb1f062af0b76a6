#pragma once
// What a roughness model is to the photon life (sim/life/photon_life.h), and how
// to add one.
//
// A roughness model decides the facet normal m that each interface event
// reflects or refracts about (SPEC section 3). It is a class, written once
// for both number types of the life (a scalar double, or an
// xsimd::batch<double> of photons: sim/simd/lanes.h), with
//
//   (constructed from its roughness type, common/roughness/, by
//   life_model in sim/roughness/roughness_models.h)
//   template <class T>
//   FacetDraw<T> draw_normal(const Vec3Of<T>& d, const BoundaryFrame<T>& frame,
//                            const MaskOf<T>& live, LaneRandom<T>& rng, T& tries,
//                            LifeCounts<T>& counts, int rounds) const;
//
// and optionally
//
//   // A throughput factor per event, and lanes whose path ends here (fate
//   // Lost; e.g. Smith G1 masking of the outgoing direction).
//   template <class T>
//   EventWeight<T> event_weight(const EventGeometry<T>& e, const MaskOf<T>& act,
//                               LaneRandom<T>& rng) const;
//   // The exit direction (once per exiting photon, scalar).
//   Vec3 exit_direction(const Vec3& d, int segments, PhotonRandom& rng) const;
//
// draw_normal rules, for every lane in `live` (leave the other lanes' random
// streams untouched: draw with rng.uniform(mask) masks within `live`):
// - return m with d.m < 0 in the lanes of `ready`; lanes whose sampler gave
//   up go in `failed` (the photon is truncated: SPEC section 3 wants none),
//   never both;
// - a rejection sampler draws at most `rounds` candidates per call, and a
//   round after the first only while another_round(pending, slow): lanes
//   neither ready nor failed are called again with the same inputs and
//   continue from their own stream (count candidates in `tries`, reset it
//   to 0 in ready or failed lanes). The scalar tracer passes rounds =
//   kMaxNormalTries, the batched one a few, so that a vector of lanes is not
//   held up by its slowest lane; both draw the same numbers for a photon.
// - count candidates in counts.normal_draws and failures in
//   counts.sampler_caps.
//
// Whether a model runs on the batched tracer is decided by its type alone:
// RunsBatched below (a draw_normal for a vector of photons, and an
// event_weight for one if it has one for a photon). Simulation and
// BatchTracer ask it (runs_batched in sim/roughness/roughness_models.h); a
// model written for T = double only runs on the reference tracer.
//
// To add a model (counted with a model whose sampler is an existing one):
// 1. its roughness type, one file common/roughness/<name>.h: its fields,
//    config reading and checks, YAML text, file attributes, info line
//    (common/roughness/roughness.h says what the type has), and its name in
//    the variant there (one line and its #include);
// 2. its sampler: one life_model overload in sim/roughness/roughness_models.h,
//    and a header sim/roughness/roughness_<name>.h with its type in
//    AnyRoughness when the sampler is new (see roughness_gaussian.h for a
//    rejection sampler, roughness_smooth.h for the simplest,
//    roughness_microfacet.h for one with an event weight);
// 3. what the analytic models make of it: its rule in
//    analytic/physical_defaults.cpp (apply_fiber_roughness) and in
//    analytic/huang2022.cpp (huang_roughness), which do not compile without;
// 4. its tests, in tests/sim/ (globbed: an oracle for its normals, and a case
//    in tests/sim/test_batch_tracer.cpp, photon by photon against the
//    reference tracer);
// 5. docs/PHYSICS.md (the model) and docs/FILE_FORMAT.md (its attributes).
// Settings, result files, checkpoints, `fiberlab info` and the comparison's
// fiber then follow from the type.
// Both tracers, the batched one's lane management, Fresnel, Stokes light,
// tilt, the consistency rule, truncation and masking's losses then apply to
// it unchanged.
#include <concepts>
#include <cstdint>
#include <vector>

#include "sim/simd/lane_packing.h"
#include "sim/simd/lane_pair.h"
#include "sim/simd/lanes.h"
#include "sim/life/random.h"

namespace fiberlab::sim {
// Weight removed from a photon by a roughness model's event weight (masking),
// and the internal path length it had travelled then: channel c lost weight *
// exp(-sigma_a[c] * path_length).
struct WeightLoss {
  double weight, path_length;
};
}  // namespace fiberlab::sim

namespace fiberlab::sim::life {

// Cap on candidate normals per event (SPEC section 3: at least 10,000).
inline constexpr int kMaxNormalTries = 100000;

// Whether a rejection sampler draws another round of candidates in this
// call: one photon until it has its normal; a vector while a lane whose
// candidates are seldom accepted (`slow`, the model's judgement) still
// waits. A lane that is usually accepted at the next candidate is cheaper
// to carry to the next step, whose other lanes move on, than a round for all.
inline bool another_round(bool pending, bool /*slow*/) { return pending; }
inline bool another_round(const MaskOf<Batch>& pending, const MaskOf<Batch>& slow) {
  return xsimd::any(pending & slow);
}
template <class M>
bool another_round(const Pair<M>& pending, const Pair<M>& slow) {
  return any(pending & slow);
}

// The macro normals of the boundary point as the photon sees them.
template <class T>
struct BoundaryFrame {
  Vec3Of<T> facing;           // n_f: the tilted normal facing the photon's side
  Vec3Of<T> untilted_facing;  // n0 (or -n0 inside): the smooth model's fallback
  // n_f = sin_n u + cos_n untilted_facing (cos_n > 0: |tilt| < 45 deg).
  T sin_n, cos_n;

  // The frame of a facing normal alone (untilted_facing: its part in the normal plane).
  static BoundaryFrame from_facing(const Vec3Of<T>& f) {
    const T cos_n = sqrt(f.y * f.y + f.z * f.z);
    const T inv = T(1.0) / cos_n;
    return {f, Vec3Of<T>(T(0.0), f.y * inv, f.z * inv), f.x, cos_n};
  }
};

template <class T>
struct FacetDraw {
  Vec3Of<T> m;
  MaskOf<T> ready;   // lanes with a normal for this event
  MaskOf<T> failed;  // lanes that gave up: truncated (never ready)
};

// One event as the optional event_weight hook sees it.
template <class T>
struct EventGeometry {
  Vec3Of<T> d_in, d_out, m;
  BoundaryFrame<T> frame;
  MaskOf<T> refracted;
};

template <class T>
struct EventWeight {
  T factor;        // multiplies the photon's throughput weight
  MaskOf<T> lost;  // the path ends here (fate Lost, its weight booked as lost)
};

// The losses a photon records: one photon, a list; a vector of lanes, each
// lane's photon a list of its own, lists[slot] (the batched tracer gives
// each photon in flight a list and hands it over with the photon). A
// photon's losses are recorded in the same order either way.
template <class T>
struct LossRecord {
  T slot;                                  // per lane: its photon's list
  std::vector<WeightLoss>* lists = nullptr;  // none: the model removes no weight
  void add(const MaskOf<T>& m, const T& weight, const T& path) {
    if (!any(m)) return;
    constexpr int kWidth = NumberTraits<T>::kWidth;
    alignas(64) double w[kWidth], p[kWidth], k[kWidth];
    store(weight, w);
    store(path, p);
    store(slot, k);
    for (std::uint64_t lanes = lane_bits(m); lanes != 0; lanes &= lanes - 1) {
      const int j = std::countr_zero(lanes);
      lists[static_cast<int>(k[j])].push_back({w[j], p[j]});
    }
  }
};
template <>
struct LossRecord<double> {
  std::vector<WeightLoss> list;
  void add(bool m, double weight, double path) {
    if (m) list.push_back({weight, path});
  }
};

// Work counters of the life, per lane (summed at the end).
template <class T>
struct LifeCounts {
  T events = T(0.0), normal_draws = T(0.0), sampler_caps = T(0.0);
};

// A model the batched tracer runs: written for its number type (Batch2,
// sim/simd/lane_pair.h), event weight included if it has one for a photon.
template <class Model>
concept RunsBatched =
    requires(const Model& m, const Vec3Of<Batch2>& d, const BoundaryFrame<Batch2>& f,
             const MaskOf<Batch2>& live, LaneRandom<Batch2>& rng, Batch2& tries,
             LifeCounts<Batch2>& counts, int rounds) {
      { m.draw_normal(d, f, live, rng, tries, counts, rounds) } -> std::same_as<FacetDraw<Batch2>>;
    } &&
    (!requires(const Model& m, const EventGeometry<double>& e, bool a, LaneRandom<double>& r) {
      m.event_weight(e, a, r);
    } || requires(const Model& m, const EventGeometry<Batch2>& e, const MaskOf<Batch2>& a,
                  LaneRandom<Batch2>& r) {
      { m.event_weight(e, a, r) } -> std::same_as<EventWeight<Batch2>>;
    });

}  // namespace fiberlab::sim::life
