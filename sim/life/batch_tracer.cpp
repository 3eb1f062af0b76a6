#include "sim/life/batch_tracer.h"

#include <algorithm>
#include <bit>
#include <memory>

#include "common/error.h"
#include "sim/simd/lane_packing.h"
#include "sim/life/source.h"

namespace fiberlab::sim {

namespace {

using life::load;
using life::load_bits;
using life::MaskOf;
// The number type the pool is stepped in: two SIMD vectors (sim/simd/lane_pair.h).
using Lanes = life::Batch2;
constexpr int W = life::NumberTraits<Lanes>::kWidth;
constexpr int kPoolLanes = 16 * W;  // photons in flight per thread

// A vector of lanes draws at most this many rounds of candidate normals per
// step, a round after the first only while a lane whose candidates are
// seldom accepted still waits (life::another_round); lanes still without a
// normal go on at the next step (see sim/roughness/roughness_model.h).
constexpr int kRoundsPerStep = 8;

// The photons in flight, structure of arrays: one column per number of
// PhotonState (the Stokes columns used by polarised light only).
struct Pool {
  enum Column {
    kPx, kPy, kDx, kDy, kDz, kInside, kPath, kSegments, kEventsHere, kTries, kWeight, kCode,
    kPhiI, kMedullaPath, kScatters, kLossList, kScalarColumns,
    kQ = kScalarColumns, kU, kV, kE1x, kE1y, kE1z, kColumns
  };
  // kSlot: the photon's slot, for the scorer (sim/life/finished_photons.h;
  // used with expected-value scoring only).
  enum BitColumn { kS0, kS1, kS2, kS3, kPhoton, kSlot, kBitColumns };
  // W spare lanes past the end: new photons, and the photons in flight
  // packed to the front, are written a whole vector at a time from any lane
  // (BatchTracer::trace_with).
  static constexpr int kLanes = kPoolLanes + W;
  alignas(64) double col[kColumns][kLanes];
  alignas(64) std::uint64_t bits[kBitColumns][kLanes];
  // kLossList: the list of weight removed from a lane's photon (a model with
  // an event weight, life::LossRecord), an index of the lists below; a
  // photon in flight holds one, and gives it back when it is handed over.
  std::vector<WeightLoss> loss_lists[kLanes];
  int free_lists[kLanes];
  int n_free = 0;
  void give_list(int lane) { col[kLossList][lane] = free_lists[--n_free]; }

  template <class T, class Light>
  life::PhotonState<T, Light> load_state(int o) const {
    life::PhotonState<T, Light> s;
    s.px = load<T>(col[kPx] + o);
    s.py = load<T>(col[kPy] + o);
    s.d = {load<T>(col[kDx] + o), load<T>(col[kDy] + o), load<T>(col[kDz] + o)};
    s.inside = load<T>(col[kInside] + o);
    s.path = load<T>(col[kPath] + o);
    s.segments = load<T>(col[kSegments] + o);
    s.events_here = load<T>(col[kEventsHere] + o);
    s.tries = load<T>(col[kTries] + o);
    s.weight = load<T>(col[kWeight] + o);
    s.code = load<T>(col[kCode] + o);
    s.medulla_path = load<T>(col[kMedullaPath] + o);
    s.scatters = load<T>(col[kScatters] + o);
    s.rng = {load_bits<T>(bits[kS0] + o), load_bits<T>(bits[kS1] + o),
             load_bits<T>(bits[kS2] + o), load_bits<T>(bits[kS3] + o)};
    if constexpr (Light::kPolarized) {
      s.light.q = load<T>(col[kQ] + o);
      s.light.u = load<T>(col[kU] + o);
      s.light.v = load<T>(col[kV] + o);
      s.light.e1 = {load<T>(col[kE1x] + o), load<T>(col[kE1y] + o), load<T>(col[kE1z] + o)};
    }
    return s;
  }

  // Writes a photon state through put(value, column): one lane, or a vector
  // of lanes wherever `put` places them. Always inline: out of line (GCC 12
  // leaves it there once trace_with grows), the state goes through memory
  // and expected-value tracing of case b loses 10% (bench_sim).
  template <class T, class Light, class Put>
  [[gnu::always_inline]] void put_state(const life::PhotonState<T, Light>& s, Put&& put) {
    put(s.px, col[kPx]);
    put(s.py, col[kPy]);
    put(s.d.x, col[kDx]);
    put(s.d.y, col[kDy]);
    put(s.d.z, col[kDz]);
    put(s.inside, col[kInside]);
    put(s.path, col[kPath]);
    put(s.segments, col[kSegments]);
    put(s.events_here, col[kEventsHere]);
    put(s.tries, col[kTries]);
    put(s.weight, col[kWeight]);
    put(s.code, col[kCode]);
    put(s.medulla_path, col[kMedullaPath]);
    put(s.scatters, col[kScatters]);
    for (int k = 0; k < 4; ++k) put(s.rng.word(k), bits[kS0 + k]);
    if constexpr (Light::kPolarized) {
      put(s.light.q, col[kQ]);
      put(s.light.u, col[kU]);
      put(s.light.v, col[kV]);
      put(s.light.e1.x, col[kE1x]);
      put(s.light.e1.y, col[kE1y]);
      put(s.light.e1.z, col[kE1z]);
    }
  }
};

// 0, 1, ..., W - 1 as stream words.
life::BitsOf<Lanes> lane_photon_offsets() {
  alignas(64) std::uint64_t idx[W];
  for (int i = 0; i < W; ++i) idx[i] = static_cast<std::uint64_t>(i);
  return life::BitsOf<Lanes>::load_aligned(idx);
}

Lanes lane_index() {
  alignas(64) double idx[W];
  for (int i = 0; i < W; ++i) idx[i] = i;
  return Lanes::load_aligned(idx);
}

// inclination() and azimuth() of the exit directions of a block, vectorised
// (truncated photons get angles too; they are not used).
void exit_angles(FinishedPhotons& f) {
  for (int i = 0; i < f.n; i += kBatchWidth) {
    const Batch x = Batch::load_aligned(f.dx + i), y = Batch::load_aligned(f.dy + i),
                z = Batch::load_aligned(f.dz + i);
    xsimd::asin(xsimd::min(Batch(1.0), xsimd::max(Batch(-1.0), x))).store_aligned(f.theta + i);
    xsimd::atan2(z, y).store_aligned(f.phi + i);
  }
}

// The exit directions of rows [n, n + k) of f that exited, through the
// model's exit hook, each from the stream `stream_of` makes of its lane's
// four words (the photon's own, or scored_exit_stream's for a scored exit).
template <class Model, class Light, class StreamOf>
void apply_exit_hook(const Model& model, const life::PhotonState<Lanes, Light>& s, std::uint64_t lanes,
                     int n, int k, FinishedPhotons& f, StreamOf stream_of) {
  alignas(64) std::uint64_t w[4][W];
  for (int q = 0; q < 4; ++q) life::pack_store(s.rng.word(q), lanes, w[q]);
  for (int j = 0; j < k; ++j) {
    if (!f.exited[n + j]) continue;
    PhotonRandom rng = stream_of(w[0][j], w[1][j], w[2][j], w[3][j]);
    const Vec3 d = exit_direction_of(model, Vec3(f.dx[n + j], f.dy[n + j], f.dz[n + j]),
                                     f.segments[n + j], rng);
    f.dx[n + j] = d.x();
    f.dy[n + j] = d.y();
    f.dz[n + j] = d.z();
  }
}

// The photons of a vector whose lanes `lanes` finished this step, appended
// to the block f (which has room for W more past them: sim/simd/lane_packing.h).
// Their fates and exit directions as finished_outcome (sim/life/tracer.h) gives
// them; a model's exit_direction needs each photon's own stream. Slots
// (sim/life/finished_photons.h) are kept with expected-value scoring only
// (kExpectedValue); analog rows carry slot 0.
template <bool kExpectedValue, class Model, class Light>
void hand_over(const Model& model, const life::PhotonState<Lanes, Light>& s, const Lanes& phi_i,
               const life::BitsOf<Lanes>& photon, const life::BitsOf<Lanes>& slot,
               std::uint64_t lanes, FinishedPhotons& f) {
  using life::pack_store;
  if (f.n == 0) f.losses.clear();  // a new block (hand_over_losses adds the photons' losses)
  const int n = f.n, k = std::popcount(lanes);
  pack_store(s.d.x, lanes, f.dx + n);
  pack_store(s.d.y, lanes, f.dy + n);
  pack_store(s.d.z, lanes, f.dz + n);
  pack_store(s.path, lanes, f.path + n);
  pack_store(s.weight, lanes, f.weight + n);
  pack_store(s.medulla_path, lanes, f.medulla_path + n);
  const std::uint64_t scattered =
      life::pack_bits(life::lane_bits(s.scatters > Lanes(0.0)), lanes);
  pack_store(phi_i, lanes, f.phi_i + n);
  pack_store(photon, lanes, f.photon + n);
  // Fates as fate_of (sim/life/tracer.h) gives them, from the code's mask bits.
  const std::uint64_t exited =
      life::pack_bits(life::lane_bits(s.code == Lanes(double(life::kExited))), lanes);
  const std::uint64_t truncated =
      life::pack_bits(life::lane_bits(s.code == Lanes(double(life::kTruncated))), lanes);
  alignas(64) double segments[W];
  pack_store(s.segments, lanes, segments);
  const std::uint64_t ended =
      life::pack_bits(life::lane_bits(s.code == Lanes(double(life::kEnded))), lanes);
  const std::uint64_t lost = ~(exited | truncated | ended);
  alignas(64) std::uint64_t slots[W] = {};
  if constexpr (kExpectedValue) pack_store(slot, lanes, slots);
  for (int j = 0; j < k; ++j) {
    f.segments[n + j] = static_cast<int>(segments[j]);
    f.exited[n + j] = (exited >> j) & 1;
    f.lost[n + j] = (lost >> j) & 1;
    f.ended[n + j] = (ended >> j) & 1;
    f.last[n + j] = true;
    f.roulette[n + j] = 0.0;
    f.slot[n + j] = static_cast<std::uint32_t>(slots[j]);
    f.scattered[n + j] = (scattered >> j) & 1;
  }
  // No exit direction for a photon that did not exit.
  for (std::uint64_t rest = ~exited & ((std::uint64_t{1} << k) - 1); rest != 0; rest &= rest - 1) {
    const int j = n + std::countr_zero(rest);
    f.dx[j] = f.dy[j] = f.dz[j] = 0.0;
  }
  if constexpr (HasExitHook<Model>)
    apply_exit_hook(model, s, lanes, n, k, f, [](auto a, auto b, auto c, auto d) {
      return PhotonRandom(life::LaneRandom<double>(a, b, c, d));
    });
  f.n = n + k;
}

// Rows on the photons' way at the lanes `lanes`' scored event (ScoredExit:
// its path, lobe and medulla numbers) with direction d, weight w (an exit
// where w > 0) and the roulette term `roulette`, appended to the block f;
// the lanes in `ended` (bits by lane) end there.
template <class Light>
void hand_over_event_rows(const life::PhotonState<Lanes, Light>& s, const life::Vec3Of<Lanes>& d, const Lanes& w,
                          const Lanes& roulette, std::uint64_t ended, const Lanes& phi_i,
                          const life::BitsOf<Lanes>& photon, const life::BitsOf<Lanes>& slot,
                          std::uint64_t lanes, FinishedPhotons& f) {
  using life::pack_store;
  const int n = f.n, k = std::popcount(lanes);
  pack_store(d.x, lanes, f.dx + n);
  pack_store(d.y, lanes, f.dy + n);
  pack_store(d.z, lanes, f.dz + n);
  pack_store(s.scored.path, lanes, f.path + n);
  pack_store(w, lanes, f.weight + n);
  pack_store(roulette, lanes, f.roulette + n);
  const std::uint64_t exited = life::pack_bits(life::lane_bits(w > Lanes(0.0)), lanes);
  pack_store(s.scored.medulla_path, lanes, f.medulla_path + n);
  const std::uint64_t scattered = life::pack_bits(life::lane_bits(s.scored.scatters > Lanes(0.0)), lanes);
  pack_store(phi_i, lanes, f.phi_i + n);
  pack_store(photon, lanes, f.photon + n);
  alignas(64) std::uint64_t slots[W];
  pack_store(slot, lanes, slots);
  alignas(64) double segments[W];
  pack_store(s.scored.segments, lanes, segments);
  const std::uint64_t ended_rows = life::pack_bits(ended, lanes);
  for (int j = 0; j < k; ++j) {
    f.segments[n + j] = static_cast<int>(segments[j]);
    f.exited[n + j] = (exited >> j) & 1;
    f.lost[n + j] = false;
    f.ended[n + j] = (ended_rows >> j) & 1;
    f.last[n + j] = (ended_rows >> j) & 1;
    f.scattered[n + j] = (scattered >> j) & 1;
    f.slot[n + j] = static_cast<std::uint32_t>(slots[j]);
  }
  f.n = n + k;
}

// The exits that the lanes `lanes` scored by expected value this step, and
// the weight Russian roulette created or destroyed there (PhotonState::scored),
// appended to the block f (sim/life/finished_photons.h): rows on the
// photon's way, except for a photon that Russian roulette ended this step
// (fate Ended, nothing left to score), whose row is also its last. A model's
// exit direction draws
// from the stream scored_exit_stream derives (sim/life/tracer.h), as the
// reference Tracer does.
// With exit splitting (sim/life/exit_splitting.h) the extra normals' exits
// come first, a row per lane that has one, then every lane's row for the
// event's own normal (with the roulette term, and the end of a photon that
// roulette ended), as the reference Tracer lists them. Returns where those
// last rows start.
// An event splits even where its own normal's branch did not leave:
// `split_only` are such lanes with nothing else to hand over (no row of
// their own). The weight a split created or destroyed rides on its first
// extra row, as roulette, so that the scorer widens the photon's room
// before booking the split's exits.
template <class Model, class Light>
int hand_over_scored(const life::LifeConfig& c, const Model& model, const life::PhotonState<Lanes, Light>& s,
                     const Lanes& phi_i, const life::BitsOf<Lanes>& photon,
                     const life::BitsOf<Lanes>& slot, std::uint64_t lanes, std::uint64_t split_only,
                     FinishedPhotons& f) {
  if (f.n == 0) f.losses.clear();  // a new block (hand_over_losses adds the photons' losses)
  Lanes own = s.scored.weight;  // the event's own normal's exit
  if (c.most_exit_normals > 1) {
    life::SplitExits<W> split;
    life::split_scored_exits(c, model, s.scored, s.rng, split);
    const Lanes created = load<Lanes>(split.created);
    for (int e = 1; e < split.n; ++e) {
      const Lanes w = load<Lanes>(split.weight[e]);
      const Lanes roulette = e == 1 ? created : Lanes(0.0);
      hand_over_event_rows(s, {load<Lanes>(split.dx[e]), load<Lanes>(split.dy[e]), load<Lanes>(split.dz[e])}, w,
                           roulette, 0, phi_i, photon, slot,
                           (lanes | split_only) & life::lane_bits((w > Lanes(0.0)) | (roulette != Lanes(0.0))), f);
    }
    own = load<Lanes>(split.weight[0]);
  }
  const int n = f.n, k = std::popcount(lanes);
  hand_over_event_rows(s, s.scored.d, own, s.scored.roulette,
                       life::lane_bits(s.code == Lanes(double(life::kEnded))), phi_i, photon, slot, lanes, f);
  if constexpr (HasExitHook<Model>)
    apply_exit_hook(model, s, lanes, n, k, f, [](auto a, auto b, auto c, auto d) {
      return scored_exit_stream(a, b, c, d);
    });
  return n;
}

// The losses of the photons of a vector whose lanes `lanes` finished this
// step, now in slots [n, ...) of the block f, handed over in their order,
// and their lists given back to the pool.
void hand_over_losses(const Lanes& list, std::uint64_t lanes, int n, Pool& pool,
                      FinishedPhotons& f) {
  alignas(64) double index[W];
  life::pack_store(list, lanes, index);
  const int k = std::popcount(lanes);
  for (int j = 0; j < k; ++j) {
    const int i = static_cast<int>(index[j]);
    for (const WeightLoss& l : pool.loss_lists[i]) f.losses.push_back({n + j, l});
    pool.loss_lists[i].clear();
    pool.free_lists[pool.n_free++] = i;
  }
}

// The same for the lanes `ended` among the lanes `scored` whose rows are
// slots [n, ...) in their order (hand_over_scored: a photon that Russian
// roulette ended has its last row there).
void hand_over_losses_of_ended(const Lanes& list, std::uint64_t scored, std::uint64_t ended, int n,
                               Pool& pool, FinishedPhotons& f) {
  alignas(64) double index[W];
  life::pack_store(list, scored, index);
  const std::uint64_t ended_rows = life::pack_bits(ended, scored);
  for (std::uint64_t rest = ended_rows; rest != 0; rest &= rest - 1) {
    const int j = std::countr_zero(rest);
    const int i = static_cast<int>(index[j]);
    for (const WeightLoss& l : pool.loss_lists[i]) f.losses.push_back({n + j, l});
    pool.loss_lists[i].clear();
    pool.free_lists[pool.n_free++] = i;
  }
}

}  // namespace

BatchTracer::BatchTracer(const Settings& s)
    : settings_(s), config_(s), roughness_(make_roughness(s)) {}

void BatchTracer::trace(double theta_i, double phi_i, const PhotonFeed& feed, const Sink& sink,
                        TracerCounters& counters) const {
  std::visit(
      [&](const auto& model) {
        using Model = std::decay_t<decltype(model)>;
        if constexpr (!life::RunsBatched<Model>) {
          throw Error("internal error: this roughness model runs on the reference tracer only");
        } else if (settings_.polarization == Polarization::Stokes) {
          if (config_.expected_value)
            trace_with<life::StokesLight<Lanes>, true>(model, theta_i, phi_i, feed, sink, counters);
          else
            trace_with<life::StokesLight<Lanes>, false>(model, theta_i, phi_i, feed, sink, counters);
        } else {
          if (config_.expected_value)
            trace_with<life::ScalarLight<Lanes>, true>(model, theta_i, phi_i, feed, sink, counters);
          else
            trace_with<life::ScalarLight<Lanes>, false>(model, theta_i, phi_i, feed, sink, counters);
        }
      },
      roughness_);
}

template <class Light, bool kExpectedValue, class Model>
void BatchTracer::trace_with(const Model& model, double theta_i, double phi_i,
                             const PhotonFeed& feed, const Sink& sink,
                             TracerCounters& counters) const {
  using OneLight = typename Light::template Rebind<double>;  // the same light, one photon
  auto pool_owner = std::make_unique<Pool>();
  Pool& pool = *pool_owner;
  // Weight removed by the model's event weights, a list per photon.
  constexpr bool kLosses = life::HasEventWeight<Model, Lanes>;
  if constexpr (kLosses)
    for (int i = 0; i < Pool::kLanes; ++i) pool.free_lists[pool.n_free++] = i;
  auto done = std::make_unique<FinishedPhotons>();
  const Source source(settings_, theta_i, phi_i);
  const EllipseCrossSection& ellipse = config_.ellipse;
  const Eigen::Vector2d beam = ellipse.beam_direction(-direction_from_angles(theta_i, phi_i));
  const Lanes iota = lane_index();
  life::LifeCounts<Lanes> counts;
  // Free photon slots (expected-value scoring: sim/life/finished_photons.h).
  constexpr bool expected_value = kExpectedValue;
  std::vector<std::uint32_t> free_slots(expected_value ? kPoolLanes : 0);
  for (int i = 0; i < static_cast<int>(free_slots.size()); ++i) free_slots[i] = static_cast<std::uint32_t>(kPoolLanes - 1 - i);
  auto take_slot = [&](int lane) {
    pool.bits[Pool::kSlot][lane] = free_slots.back();
    free_slots.pop_back();
  };

  // New photons into lanes [o, o + W), photons first, first + 1, ...: the
  // Source's streams and impact parameters and the life's start, a vector at
  // a time (a fixed incident direction). Lanes past the photons wanted are
  // free lanes (or the pool's spare ones): what is written there is never read.
  const bool vector_launch = source.fixed_direction();
  const Vec3 d_fixed = -direction_from_angles(theta_i, phi_i);
  const life::Vec3Of<Lanes> d_lanes{Lanes(d_fixed.x()), Lanes(d_fixed.y()), Lanes(d_fixed.z())};
  auto launch_vector = [&](int o, std::uint64_t first_photon) {
    const life::BitsOf<Lanes> photon = life::BitsOf<Lanes>(first_photon) + lane_photon_offsets();
    const auto lanes = source.template launch_lanes<Lanes>(photon);
    Lanes pv, pw;
    ellipse.entry_point_in_beam(beam, lanes.h, pv, pw);
    pool.put_state(life::start_photon<Light>(pv, pw, d_lanes, lanes.rng),
                   [o](const auto& x, auto* column) { life::store_unaligned(x, column + o); });
    photon.store_unaligned(pool.bits[Pool::kPhoton] + o);
  };
  // A new photon into lane i: the Source's launch, the life's start.
  auto launch = [&](int i, std::uint64_t photon) {
    const LaunchedPhoton p = source.launch(photon);
    const Vec3 d = -p.wi;
    const Point2 entry = ellipse.entry_point_in_beam(
        source.fixed_direction() ? beam : ellipse.beam_direction(d), p.h);
    pool.put_state(life::start_photon<OneLight>(entry, d, p.rng.core()),
                   [i](const auto& x, auto* column) { column[i] = x; });
    pool.col[Pool::kPhiI][i] = p.phi_i;
    pool.bits[Pool::kPhoton][i] = photon;
    if constexpr (kLosses) pool.give_list(i);
  };
  auto flush = [&] {
    done->clear_tail();
    exit_angles(*done);
    sink(*done);
    done->n = 0;
  };
  // A pass over the pool appends at most every lane it holds, and a vector's
  // worth of scratch past them (sim/simd/lane_packing.h).
  // With expected-value scoring every lane may also hand over an exit it
  // scored: twice that. The analog estimator keeps blocks of at most half
  // the capacity, whose columns stay in the caches as well as the scorer's.
  constexpr int kFlushAbove = expected_value
                                  ? FinishedPhotons::kCapacity - 2 * (kPoolLanes + W)
                                  : FinishedPhotons::kCapacity / 2 - (kPoolLanes + W);
  static_assert(kFlushAbove >= kPoolLanes - W, "blocks of at least about a pool of photons");
  static_assert((kMaxExitNormals + 2) * W <= FinishedPhotons::kCapacity,
                "a vector's split exits, ends and scratch fit in an empty block");

  // Photons [next, end) of the current run are still to launch.
  std::uint64_t next = 0, end = 0;
  bool fed_out = false;
  auto more_to_launch = [&] {
    while (next == end && !fed_out) {
      const PhotonRun run = feed();
      fed_out = run.n == 0;
      next = run.first;
      end = run.first + run.n;
    }
    return next < end;
  };
  int n_active = 0;
  while (true) {
    if (vector_launch) {
      while (n_active < kPoolLanes && more_to_launch()) {
        launch_vector(n_active, next);
        const int n = static_cast<int>(std::min<std::uint64_t>(
            std::min(W, kPoolLanes - n_active), end - next));
        if constexpr (expected_value)
          for (int j = 0; j < n; ++j) take_slot(n_active + j);
        if constexpr (kLosses)
          for (int i = n_active; i < n_active + n; ++i) pool.give_list(i);
        n_active += n;
        next += n;
      }
    } else {
      while (n_active < kPoolLanes && more_to_launch()) {
        if constexpr (expected_value) take_slot(n_active);
        launch(n_active++, next++);
      }
    }
    if (n_active == 0) break;
    if (done->n > kFlushAbove) flush();
    // One step for every photon in flight, a vector at a time. The finished
    // ones go to the block; the others are packed to the front of the pool as
    // the pass goes (`kept` never passes the vector being stepped, which is
    // already loaded). The order of photons in the pool does not matter:
    // tallies are exact integer sums.
    int kept = 0;
    for (int o = 0; o < n_active; o += W) {
      // Exit splitting hands over up to most_exit_normals rows per lane:
      // room for them, the photons' ends and a vector of scratch.
      if (config_.most_exit_normals > 1 &&
          done->n + (config_.most_exit_normals + 2) * W > FinishedPhotons::kCapacity)
        flush();
      const MaskOf<Lanes> live = (iota + Lanes(o)) < Lanes(n_active);
      auto s = pool.load_state<Lanes, Light>(o);
      if constexpr (kLosses) s.losses = {load<Lanes>(pool.col[Pool::kLossList] + o), pool.loss_lists};
      // A fixed incident direction keeps phi_i out of the pool.
      const Lanes phi_lanes = vector_launch ? Lanes(phi_i) : load<Lanes>(pool.col[Pool::kPhiI] + o);
      const life::BitsOf<Lanes> photon = load_bits<Lanes>(pool.bits[Pool::kPhoton] + o);
      life::BitsOf<Lanes> slot;
      if constexpr (expected_value) slot = load_bits<Lanes>(pool.bits[Pool::kSlot] + o);
      life::step<expected_value>(config_, model, s, live, counts, kRoundsPerStep);
      const MaskOf<Lanes> at_boundary = s.code == Lanes(life::kAtBoundary);
      const std::uint64_t finished = life::lane_bits(live & !at_boundary);
      const std::uint64_t in_flight = life::lane_bits(live & at_boundary);
      std::uint64_t end_rows = finished;  // photons whose last row is handed over below
      if constexpr (expected_value) {
        // A photon's scored exit (or roulette) goes before its end, if it
        // ended this step; one that roulette ended ends on that row.
        const std::uint64_t scored = life::lane_bits(
            live & ((s.scored.weight > Lanes(0.0)) | (s.scored.roulette != Lanes(0.0))));
        const std::uint64_t ended = life::lane_bits(live & (s.code == Lanes(double(life::kEnded))));
        // An event of a lobe with several normals splits even where its own
        // branch did not leave (sim/life/exit_splitting.h).
        const std::uint64_t split_only =
            config_.most_exit_normals > 1
                ? life::lane_bits(live & (life::normals_of_event(config_, s.scored) > Lanes(1.0))) & ~scored
                : 0;
        end_rows = finished & ~ended;
        if ((scored | split_only) != 0) {
          const int n_before =
              hand_over_scored(config_, model, s, phi_lanes, photon, slot, scored, split_only, *done);
          if constexpr (kLosses)
            if (ended != 0) hand_over_losses_of_ended(s.losses.slot, scored, ended, n_before, pool, *done);
        }
        if (finished != 0) {
          alignas(64) std::uint64_t freed[W];
          life::pack_store(slot, finished, freed);
          for (int j = 0; j < std::popcount(finished); ++j)
            free_slots.push_back(static_cast<std::uint32_t>(freed[j]));
        }
      }
      if (end_rows != 0) {
        const int n_before = done->n;
        hand_over<expected_value>(model, s, phi_lanes, photon, slot, end_rows, *done);
        if constexpr (kLosses) hand_over_losses(s.losses.slot, end_rows, n_before, pool, *done);
      }
      if constexpr (kLosses)
        life::pack_store(s.losses.slot, in_flight, pool.col[Pool::kLossList] + kept);
      pool.put_state(s, [&](const auto& x, auto* column) { life::pack_store(x, in_flight, column + kept); });
      if (!vector_launch) life::pack_store(phi_lanes, in_flight, pool.col[Pool::kPhiI] + kept);
      life::pack_store(photon, in_flight, pool.bits[Pool::kPhoton] + kept);
      if constexpr (expected_value) life::pack_store(slot, in_flight, pool.bits[Pool::kSlot] + kept);
      kept += std::popcount(in_flight);
    }
    n_active = kept;
  }
  if (done->n > 0) flush();
  counters.events += static_cast<long>(life::lane_sum(counts.events));
  counters.normal_draws += static_cast<long>(life::lane_sum(counts.normal_draws));
  counters.sampler_caps += static_cast<long>(life::lane_sum(counts.sampler_caps));
}

}  // namespace fiberlab::sim
