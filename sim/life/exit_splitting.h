#pragma once
// Exit splitting (Settings::exit_normals; docs/PHYSICS.md "Estimator"), under
// expected-value scoring (SPEC section 5). An event whose leaving branch was
// scored, with weight w s_1 (s_1: that branch's leaving probability P_1
// times its masking factor G1_1), spreads that weight over K leaving
// directions: its own normal's, and those of K - 1 more normals drawn at the
// same event from the same distribution (the roughness model's draw, for the
// same direction and boundary frame). Normal k gets w s_1 s_k / S, with
// S = s_1 + ... + s_K and s_k = P_k G1_k where normal k's leaving branch
// leaves the fiber (SPEC section 3's consistency rule), 0 otherwise.
//
// - Unbiased: the K normals are exchangeable (independent, one
//   distribution), so with f(j, k) = E[s_j s_k 1(b_k = b) / S] the sum over
//   j and k is K E[s 1(b_1 = b)], and exchangeability makes it K times the
//   sum over k of f(1, k), which is the split score of bin b: its
//   expectation is E[s 1(b_1 = b)], the expected-value score of the bin.
//   The photon's own normal must be one of the K, drawn as the others are.
// - The photon's weight and path are those without splitting: the total it
//   scores at the event is still w s_1, it goes on with w (1 - P_1) along
//   its own normal, so the ledger closes per photon as before. The extra
//   normals come from streams derived from the photon's (extra_normal_stream), not
//   from its own.
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
#include <cstdint>

#include "sim/life/photon_life.h"

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

// A scored exit's event as split_scored_exits reads it: d_in, px, py, inside.
inline constexpr int kSplitInputs = 6;

// The extra normals still to draw, as (lane l, k) pairs, k = 1 ..
// normals[l] - 1, lane by lane, and the vector of W of them being drawn: a
// pair keeps its vector lane (its event, stream and candidate count) until
// its normal is drawn or its sampler gives up, and refill() gives the lanes
// that are free the next pairs, so that no vector waits for its slowest
// lane (a rejection sampler's). A free lane repeats a busy lane's inputs;
// its numbers are never used.
template <int W>
struct ExtraNormalQueue {
  explicit ExtraNormalQueue(const double* normals) : normals_(normals) {}
  alignas(64) double in[kSplitInputs][W], tries[W];
  alignas(64) std::uint64_t words[4][W];
  int lane[W], k[W];
  bool is_busy[W] = {};

  // Fills the free lanes, their streams extra_normal_stream's of the
  // lanes' split_hash (`hash`, by lane of the photons' vector) and k,
  // computed a vector at a time; false once no pair is left to draw.
  template <class T>
  bool refill(const double (*event)[W], const std::uint64_t* hash) {
    int some = -1;
    bool fresh[W] = {};
    alignas(64) std::uint64_t pair_hash[W] = {}, pair_k[W] = {};
    for (int j = 0; j < W; ++j) {
      if (!is_busy[j] && next(lane[j], k[j])) {
        for (int q = 0; q < kSplitInputs; ++q) in[q][j] = event[q][lane[j]];
        pair_hash[j] = hash[lane[j]];
        pair_k[j] = static_cast<std::uint64_t>(k[j]);
        tries[j] = 0.0;
        is_busy[j] = fresh[j] = true;
      }
      if (is_busy[j]) some = j;
    }
    if (some < 0) return false;
    const LaneRandom<T> r = extra_normal_stream<T>(load_bits<T>(pair_hash), load_bits<T>(pair_k));
    alignas(64) std::uint64_t w[4][W];
    for (int q = 0; q < 4; ++q) store_bits(r.word(q), w[q]);
    for (int j = 0; j < W; ++j) {
      if (fresh[j])
        for (int q = 0; q < 4; ++q) words[q][j] = w[q][j];
      if (!is_busy[j]) {
        for (int q = 0; q < kSplitInputs; ++q) in[q][j] = in[q][some];
        for (int q = 0; q < 4; ++q) words[q][j] = words[q][some];
        tries[j] = 0.0;
      }
    }
    return true;
  }
  template <class T>
  MaskOf<T> busy() const {
    alignas(64) double b[W];
    for (int j = 0; j < W; ++j) b[j] = is_busy[j] ? 1.0 : 0.0;
    return load<T>(b) != T(0.0);
  }
  template <class T>
  LaneRandom<T> stream() const {
    return {load_bits<T>(words[0]), load_bits<T>(words[1]), load_bits<T>(words[2]), load_bits<T>(words[3])};
  }

 private:
  bool next(int& l, int& kk) {
    while (next_lane_ < W && next_k_ >= static_cast<int>(normals_[next_lane_])) ++next_lane_, next_k_ = 1;
    if (next_lane_ == W) return false;
    l = next_lane_;
    kk = next_k_++;
    return true;
  }
  const double* normals_;
  int next_lane_ = 0, next_k_ = 1;
};

// The scored exits e of a vector of photons (ScoredExit: this step's, with
// their streams `rng` after the step) spread over c.exit_normals[lobe p]
// normals each. The extra normals of all the lanes' splits are drawn a
// vector at a time, whichever lanes they belong to, each from its own
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
  const MaskOf<T> scored = e.weight > T(0.0);
  if (c.most_exit_normals == 1 || !any(scored)) return;
  // The lanes' events, streams and normals (1 where nothing was scored).
  alignas(64) double event[kSplitInputs][W], normals[W], share[W];
  alignas(64) std::uint64_t hash[W];
  store(e.d_in.x, event[0]);
  store(e.d_in.y, event[1]);
  store(e.d_in.z, event[2]);
  store(e.px, event[3]);
  store(e.py, event[4]);
  store(e.inside, event[5]);
  store(select(scored, exit_normals_at(c, e.segments), T(1.0)), normals);
  store(e.share, share);
  store_bits(split_hash(rng), hash);
  for (int l = 0; l < W; ++l) out.n = std::max(out.n, static_cast<int>(normals[l]));
  for (int k = 1; k < out.n; ++k)
    for (int l = 0; l < W; ++l) out.weight[k][l] = 0.0;
  ExtraNormalQueue<W> queue(normals);
  while (queue.template refill<T>(event, hash)) {
    const MaskOf<T> busy = queue.template busy<T>();
    LaneRandom<T> r = queue.template stream<T>();
    T tries = load<T>(queue.tries);
    const SplitEvent<T> ev =
        split_event(c, Vec3Of<T>(load<T>(queue.in[0]), load<T>(queue.in[1]), load<T>(queue.in[2])),
                    load<T>(queue.in[3]), load<T>(queue.in[4]), load<T>(queue.in[5]));
    LifeCounts<T> counts;  // not the run's: an extra normal is not an event
    const FacetDraw<T> f = model.draw_normal(ev.d_in, ev.frame, busy, r, tries, counts, kMaxNormalTries);
    const ExtraExit<T> x = extra_exit(model, ev, f.m, f.ready, r);
    alignas(64) double ox[W], oy[W], oz[W], os[W];
    store(x.d.x, ox);
    store(x.d.y, oy);
    store(x.d.z, oz);
    store(x.share, os);
    store(tries, queue.tries);
    for (int q = 0; q < 4; ++q) store_bits(r.word(q), queue.words[q]);
    alignas(64) double done[W];
    store(ones<T>(f.ready | f.failed), done);
    for (int j = 0; j < W; ++j) {
      if (!queue.is_busy[j] || done[j] == 0.0) continue;
      const int l = queue.lane[j], k = queue.k[j];
      out.dx[k][l] = ox[j];
      out.dy[k][l] = oy[j];
      out.dz[k][l] = oz[j];
      out.weight[k][l] = os[j];  // 0 where the draw gave up
      queue.is_busy[j] = false;
    }
  }
  // Normal k's weight w s_1 s_k / S (S >= s_1 > 0 where a lane scored; the
  // shares summed in the order of k, whatever order the pairs were drawn
  // in, so that S does not depend on the photon's neighbours in the
  // vector); a lane with one normal keeps its weight as it is.
  for (int l = 0; l < W; ++l) {
    if (normals[l] < 2.0) continue;
    double extra = 0.0;
    for (int k = 1; k < static_cast<int>(normals[l]); ++k) extra += out.weight[k][l];
    const double scale = out.weight[0][l] / (share[l] + extra);
    out.weight[0][l] = scale * share[l];
    for (int k = 1; k < static_cast<int>(normals[l]); ++k) out.weight[k][l] *= scale;
  }
}

}  // namespace fiberlab::sim::life
