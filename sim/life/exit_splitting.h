#pragma once
// Exit splitting (Settings::exit_normals; docs/PHYSICS.md "Exit splitting"),
// under expected-value scoring (SPEC section 5). At every interface event of
// a lobe p with K = exit_normals[p] > 1, the exit the event scores is
// estimated from K exits instead of one: the event's own normal's (its
// leaving branch, scored w s_1 as with K = 1), and those of K - 1 more
// normals drawn at the same event from the same distribution (the roughness
// model's draw, for the same direction and boundary frame). Normal k's exit
// is scored w s_k / K, with w the photon's weight before the event and
// s_k = P_k G1_k (normal k's leaving probability times its masking factor)
// where its leaving branch leaves the fiber (SPEC section 3's consistency
// rule), 0 otherwise.
//
// - Unbiased: each of the K terms is 1 / K of an expected-value score of
//   the event, since every normal has the distribution of the event's own
//   given the photon's state before it. So an event splits whether or not
//   its own leaving branch left (s_1 = 0): its extra normals' exits are part
//   of the estimate. (Weights in proportion to s_1, w s_1 s_k / S, are
//   unbiased too, by exchangeability, but they keep each event's total at
//   the own w s_1: nothing where the own branch did not leave, all of it
//   where it did. That variance stays however large K is; the mean over
//   the K normals averages it out.)
// - The photon's path and weight are those without splitting: it goes on
//   with w (1 - P_1) along its own normal (or as the analog choice where
//   its leaving branch did not leave). The extra normals come from streams
//   derived from the photon's (extra_normal_stream), not from its own.
// - The ledger closes per photon: the event scores w (s_1 + ... + s_K) / K
//   in total instead of the own w s_1; the difference is weight the split
//   created (> 0) or destroyed (< 0), booked with the photon's roulette
//   term (on the event's first extra row, so that the scorer widens the
//   photon's room before booking the split's exits). Its expectation is 0.
// - The photon's first event (outside, at its entry point, no event there
//   before; ScoredExit::first) draws more: each extra normal also gets an
//   impact parameter h uniform in [-1, 1) and its own entry point, so that
//   the K are K independent first events. Where most of R's variance is
//   that of h (which bins a given h can reach), this removes it.
// - What it buys: where an event's roughness spreads its exit over many
//   bins, the variance of those bins falls by up to K; the cost is K - 1
//   normal draws and exit rows (the figure of merit per lobe: docs/PHYSICS.md).
// An extra normal whose draw gives up (a rejection sampler's cap, SPEC
// section 3: never seen in practice) counts as s_k = 0; it does not
// truncate the photon.
// SPEC section 5 does not name exit splitting (it allows expected-value
// scoring, roulette and stratified h, each changing the variance and never
// the expectation): fiberlab's own, held to analog runs by
// tests/sim/test_exit_normals.cpp (docs/PHYSICS.md "Exit splitting").
#include <algorithm>
#include <bit>
#include <cstdint>

#include "sim/life/photon_life.h"
#include "sim/simd/lane_packing.h"
#include "sim/simd/lane_permute.h"

namespace fiberlab::sim::life {

// The streams the extra normals of a split are drawn from, one per normal
// k >= 1 (so that the batched tracer may draw the normals of several
// photons' splits in one vector): SplitMix64 over split_hash, a hash of the
// photon's stream state after the step that scored the exit (salted apart
// from the exit blur's stream, sim/life/tracer.h scored_exit_stream), plus
// k times the golden ratio's word.
template <class T>
BitsOf<T> split_hash(const LaneRandom<T>& r) {
  using Bits = BitsOf<T>;
  constexpr std::uint64_t kSalt = 0x5851f42d4c957f2dULL;
  return splitmix(r.word(0) ^ splitmix(r.word(1) ^ splitmix(r.word(2) ^ splitmix(r.word(3) ^ Bits(kSalt)))));
}
template <class T>
LaneRandom<T> extra_normal_stream(const BitsOf<T>& hash, const BitsOf<T>& k) {
  BitsOf<T> x = splitmix(hash + times(k, 0x9e3779b97f4a7c15ULL));
  BitsOf<T> s[4];
  for (auto& w : s) w = x = splitmix(x);
  return {s[0], s[1], s[2], s[3]};
}

// One extra normal m of a split, drawn at the event a scored exit came
// from (ScoredExit's d_in, px, py, inside): its leaving branch's direction
// and share s_k = P_k G1_k (0 outside `ready`, or where the branch does not
// leave).
template <class T>
struct ExtraExit {
  Vec3Of<T> d;
  T share;
};

// The boundary frame and indices of such an event.
template <class T>
struct SplitEvent {
  MaskOf<T> inside;
  Vec3Of<T> d_in, n0;
  BoundaryFrame<T> frame;
  InterfaceIndex<T> index;
};

template <class T>
SplitEvent<T> split_event(const LifeConfig& c, const Vec3Of<T>& d_in, const T& px, const T& py, const T& inside) {
  SplitEvent<T> e;
  e.inside = inside != T(0.0);
  e.d_in = d_in;
  e.n0 = c.ellipse.normal_at(px, py);
  e.frame = boundary_frame(c, e.n0, e.inside);
  e.index = interface_index<T>(c, e.inside);
  return e;
}

template <class T, class Model>
ExtraExit<T> extra_exit(const Model& model, const SplitEvent<T>& e, const Vec3Of<T>& m, const MaskOf<T>& ready,
                        LaneRandom<T>& rng) {
  const T cos_i = min(T(1.0), max(T(0.0), -e.d_in.dot(m)));
  const FresnelReflectanceOf<T> fr = fresnel_reflectance(cos_i, e.index.eta_rel, e.index.ratio);
  ExtraExit<T> out;
  const MaskOf<T> leaves = leaving_branch(ExitScoring<T>{ready, e.inside, e.n0}, e.d_in, m, fr.tir, cos_i, fr.cos_t,
                                          e.index.ratio, out.d);
  out.share = select(leaves, leaving_probability(e.inside, fr.F), T(0.0));
  if constexpr (HasEventWeight<Model, T>) {
    const EventWeight<T> w = model.event_weight(EventGeometry<T>{e.d_in, out.d, m, e.frame, e.inside}, leaves, rng);
    out.share = select(leaves & !w.lost, out.share * w.factor, T(0.0));
  }
  return out;
}

// A scored exit spread over its normals, per lane l of the vector of
// photons that scored it: entry 0 the event's own normal's exit, entries
// 1 .. n - 1 the extra normals' (weight 0 where a lane has fewer).
template <int W>
struct SplitExits {
  int n = 1;
  alignas(64) double dx[kMaxExitNormals][W], dy[kMaxExitNormals][W], dz[kMaxExitNormals][W];
  alignas(64) double weight[kMaxExitNormals][W];
  // Per lane, the weight the split created (> 0) or destroyed (< 0)
  // (resampled_weights), booked as the ledger's roulette term.
  alignas(64) double created[W];
};

// Settings::exit_normals for the lobes p of the lanes.
template <class T>
T exit_normals_at(const LifeConfig& c, const T& p) {
  constexpr int kLast = LifeConfig::kExitNormalsLobes - 1;
  T k(static_cast<double>(c.exit_normals[kLast]));
  for (int q = kLast - 1; q >= 0; --q)
    k = select(p == T(static_cast<double>(q)), T(static_cast<double>(c.exit_normals[q])), k);
  return k;
}

// Per lane, the normals its event's exit is estimated from: exit_normals[p]
// where an interface event acted (whether or not its own branch left), 1
// where none did. The lanes above 1 split (split_scored_exits).
template <class T>
T normals_of_event(const LifeConfig& c, const ScoredExit<T>& e) {
  return select(e.acted != T(0.0), exit_normals_at(c, e.segments), T(1.0));
}

// The extra normals still to draw, as (lane l, k) pairs, k = 1 ..
// normals[l] - 1, lane by lane, and the vector of W of them being drawn: a
// pair keeps its vector lane (its event, stream and candidate count) until
// its normal is drawn or its sampler gives up, and refill() gives the lanes
// that are free the next pairs, so that no vector waits for its slowest
// lane (a rejection sampler's). What a lane draws with is moved to it from
// the photons' lanes by lane permutations (sim/simd/lane_permute.h): a free
// lane takes a busy lane's (its numbers are never used).
template <int W>
struct ExtraNormalQueue {
  explicit ExtraNormalQueue(const double* normals) {
    for (int l = 0; l < W; ++l)
      for (int k = 1; k < static_cast<int>(normals[l]); ++k) pairs_[n_pairs_++] = {l, k};
  }
  // Per vector lane j, the photon lane of its pair and its k.
  alignas(64) std::uint64_t lane[W] = {}, k[W] = {};
  std::uint64_t busy = 0;  // bits: the lanes with a pair

  // Gives the free lanes the next pairs; `fresh` their bits. False once no
  // lane has a pair.
  bool refill(std::uint64_t& fresh) {
    fresh = 0;
    for (int j = 0; j < W && next_ < n_pairs_; ++j) {
      if ((busy >> j) & 1) continue;
      lane[j] = static_cast<std::uint64_t>(pairs_[next_].lane);
      k[j] = static_cast<std::uint64_t>(pairs_[next_].k);
      ++next_;
      fresh |= std::uint64_t{1} << j;
    }
    busy |= fresh;
    if (busy == 0) return false;
    const int some = std::countr_zero(busy);
    for (int j = 0; j < W; ++j)
      if (!((busy >> j) & 1)) lane[j] = lane[some];
    return true;
  }

 private:
  struct PairOf {
    int lane, k;
  };
  PairOf pairs_[W * (kMaxExitNormals - 1)];
  int n_pairs_ = 0, next_ = 0;
};

// An event's K exits (lane l of `out`: entry 0 the photon's own, w s_1, or
// 0 where its leaving branch did not leave; entries k >= 1 the shares s_k
// of the extra normals) scored w s_k / K each, w = `weight_in`, the
// photon's weight before the event. What their total adds to or takes from
// the own w s_1 goes to out.created.
template <int W>
void resampled_weights(SplitExits<W>& out, int l, int normals, double weight_in) {
  const double per_event = 1.0 / normals;
  const double own = out.weight[0][l];
  out.weight[0][l] = own / normals;
  double total = out.weight[0][l];
  for (int k = 1; k < normals; ++k) {
    out.weight[k][l] = weight_in * out.weight[k][l] * per_event;
    total += out.weight[k][l];
  }
  out.created[l] = total - own;
}

// The exits of the events of a vector of photons (ScoredExit: this step's,
// with their streams `rng` after the step) estimated from
// c.exit_normals[lobe p] normals each. The extra normals of all the lanes'
// splits are drawn a vector at a time, whichever lanes they belong to, each from its own
// stream (extra_normal_stream): a photon gets the same numbers traced alone
// (T = double, the reference tracer) or in a vector. Scalar light only
// (Settings refuses exit_normals > 1 with Stokes light).
template <class T, class Model, int W = NumberTraits<T>::kWidth>
void split_scored_exits(const LifeConfig& c, const Model& model, const ScoredExit<T>& e, const LaneRandom<T>& rng,
                        SplitExits<W>& out) {
  out.n = 1;
  store(e.d.x, out.dx[0]);
  store(e.d.y, out.dy[0]);
  store(e.d.z, out.dz[0]);
  store(e.weight, out.weight[0]);
  for (double& x : out.created) x = 0.0;
  if (c.most_exit_normals == 1) return;
  const T lane_normals = normals_of_event(c, e);
  if (!any(lane_normals > T(1.0))) return;
  alignas(64) double normals[W];
  store(lane_normals, normals);
  const MaskOf<T> first = e.first != T(0.0);
  const BitsOf<T> hash = split_hash(rng);
  for (int l = 0; l < W; ++l) out.n = std::max(out.n, static_cast<int>(normals[l]));
  for (int k = 1; k < out.n; ++k)
    for (int l = 0; l < W; ++l) out.weight[k][l] = 0.0;
  ExtraNormalQueue<W> queue(normals);
  // Each vector lane's stream and candidate count (its pair's).
  LaneRandom<T> r(BitsOf<T>(0), BitsOf<T>(0), BitsOf<T>(0), BitsOf<T>(0));
  T tries(0.0);
  // A first event's pair: its entry point (drawn once per pair, from the
  // photon's beam direction, computed once per photon).
  T entry_v(0.0), entry_w(0.0), beam_v(0.0), beam_w(0.0);
  if (any(first)) c.ellipse.beam_direction_of(e.d_in.y, e.d_in.z, beam_v, beam_w);
  std::uint64_t fresh = 0;
  while (queue.refill(fresh)) {
    const BitsOf<T> lane = load_bits<T>(queue.lane);
    const MaskOf<T> busy = mask_of_bits<T>(queue.busy), is_fresh = mask_of_bits<T>(fresh);
    if (fresh != 0) {
      const LaneRandom<T> seeded = extra_normal_stream<T>(permute_lanes(hash, lane), load_bits<T>(queue.k));
      const auto m = bits_mask(is_fresh);
      r = LaneRandom<T>(select(m, seeded.word(0), r.word(0)), select(m, seeded.word(1), r.word(1)),
                        select(m, seeded.word(2), r.word(2)), select(m, seeded.word(3), r.word(3)));
      tries = select(is_fresh, T(0.0), tries);
    }
    const MaskOf<T> at_entry = permute_lanes(e.first, lane) != T(0.0);
    // A first event's pair draws its impact parameter first from its fresh stream.
    const MaskOf<T> new_entry = is_fresh & at_entry;
    if (any(new_entry)) {
      const T h = T(2.0) * r.uniform(new_entry) - T(1.0);
      T v, w;
      c.ellipse.entry_point_in_beam(permute_lanes(beam_v, lane), permute_lanes(beam_w, lane), h, v, w);
      entry_v = select(new_entry, v, entry_v);
      entry_w = select(new_entry, w, entry_w);
    }
    const Vec3Of<T> d_in(permute_lanes(e.d_in.x, lane), permute_lanes(e.d_in.y, lane),
                         permute_lanes(e.d_in.z, lane));
    const T px = select(at_entry, entry_v, permute_lanes(e.px, lane));
    const T py = select(at_entry, entry_w, permute_lanes(e.py, lane));
    const SplitEvent<T> ev = split_event(c, d_in, px, py, permute_lanes(e.inside, lane));
    LifeCounts<T> counts;  // not the run's: an extra normal is not an event
    const FacetDraw<T> f = model.draw_normal(ev.d_in, ev.frame, busy, r, tries, counts, kMaxNormalTries);
    const ExtraExit<T> x = extra_exit(model, ev, f.m, f.ready, r);
    std::uint64_t done = lane_bits(f.ready | f.failed) & queue.busy;
    if (done == 0) continue;
    alignas(64) double ox[W], oy[W], oz[W], os[W];
    store(x.d.x, ox);
    store(x.d.y, oy);
    store(x.d.z, oz);
    store(x.share, os);
    queue.busy &= ~done;
    for (; done != 0; done &= done - 1) {
      const int j = std::countr_zero(done);
      const std::size_t l = queue.lane[j], k = queue.k[j];
      out.dx[k][l] = ox[j];
      out.dy[k][l] = oy[j];
      out.dz[k][l] = oz[j];
      out.weight[k][l] = os[j];  // 0 where the draw gave up
    }
  }
  alignas(64) double weight_in[W];
  store(e.weight_in, weight_in);
  for (int l = 0; l < W; ++l)
    if (normals[l] >= 2.0) resampled_weights(out, l, static_cast<int>(normals[l]), weight_in[l]);
}

}  // namespace fiberlab::sim::life
