#include "sim/batch_tracer.h"

#include <algorithm>
#include <cstring>
#include <memory>

#include "common/error.h"
#include "sim/source.h"

namespace fiberlab::sim {

namespace {

using life::load;
using life::load_bits;
using life::store;
using life::store_bits;
using life::MaskOf;
constexpr int W = kBatchWidth;
static_assert(W <= 8, "the hand-over reads a vector's finished flags into one 64-bit word");
constexpr int kPoolLanes = 32 * W;  // photons in flight per thread

// A vector of lanes draws at most this many rounds of candidate normals per
// step, a round after the first only while a lane whose candidates are
// seldom accepted still waits (life::another_round); lanes still without a
// normal go on at the next step (see sim/roughness_model.h).
constexpr int kRoundsPerStep = 8;

// The photons in flight, structure of arrays: one column per number of
// PhotonState (the Stokes columns used by polarised light only).
struct Pool {
  enum Column {
    kPx, kPy, kDx, kDy, kDz, kInside, kPath, kSegments, kEventsHere, kTries, kWeight, kCode,
    kPhiI, kScalarColumns,
    kQ = kScalarColumns, kU, kV, kE1x, kE1y, kE1z, kColumns
  };
  enum BitColumn { kS0, kS1, kS2, kS3, kPhoton, kBitColumns };
  // W spare lanes past the end: new photons are written a whole vector at a
  // time from any lane (launch_vector in BatchTracer::trace_with).
  static constexpr int kLanes = kPoolLanes + W;
  alignas(64) double col[kColumns][kLanes];
  alignas(64) std::uint64_t bits[kBitColumns][kLanes];

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

  // The state of lanes [o, o + W) (T a vector; o a multiple of W unless
  // kAligned is false) or of lane o (T = double).
  template <class T, class Light, bool kAligned = true>
  void store_state(int o, const life::PhotonState<T, Light>& s) {
    const auto put = [&](const auto& x, auto* column) {
      if constexpr (kAligned) {
        if constexpr (std::is_same_v<std::decay_t<decltype(*column)>, double>) store(x, column + o);
        else store_bits(x, column + o);
      } else {
        life::store_unaligned(x, column + o);
      }
    };
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

  void move(int to, int from, bool polarized) {
    const int n = polarized ? kColumns : kScalarColumns;
    for (int c = 0; c < n; ++c) col[c][to] = col[c][from];
    for (int c = 0; c < kBitColumns; ++c) bits[c][to] = bits[c][from];
  }
};

// 0, 1, ..., W - 1 as stream words.
life::BitsOf<Batch> lane_photon_offsets() {
  alignas(64) std::uint64_t idx[W];
  for (int i = 0; i < W; ++i) idx[i] = static_cast<std::uint64_t>(i);
  return life::BitsOf<Batch>::load_aligned(idx);
}

Batch lane_index() {
  alignas(64) double idx[W];
  for (int i = 0; i < W; ++i) idx[i] = i;
  return Batch::load_aligned(idx);
}

// inclination() and azimuth() of the exit directions of a block, vectorised
// (truncated photons get angles too; they are not used).
void exit_angles(FinishedPhotons& f) {
  for (int i = 0; i < f.n; i += W) {
    const Batch x = Batch::load_aligned(f.dx + i), y = Batch::load_aligned(f.dy + i),
                z = Batch::load_aligned(f.dz + i);
    xsimd::asin(xsimd::min(Batch(1.0), xsimd::max(Batch(-1.0), x))).store_aligned(f.theta + i);
    xsimd::atan2(z, y).store_aligned(f.phi + i);
  }
}

}  // namespace

BatchTracer::BatchTracer(const Settings& s)
    : settings_(s), config_(s), roughness_(make_roughness(s)) {}

void BatchTracer::trace(double theta_i, double phi_i, std::uint64_t first, std::uint64_t n,
                        const Sink& sink, TracerCounters& counters) const {
  std::visit(
      [&](const auto& model) {
        using Model = std::decay_t<decltype(model)>;
        if constexpr (requires { Model::kScalarOnly; }) {
          throw Error("internal error: this roughness model runs on the reference tracer only");
        } else if (settings_.polarization == Polarization::Stokes)
          trace_with<life::StokesLight<Batch>>(model, theta_i, phi_i, first, n, sink, counters);
        else
          trace_with<life::ScalarLight<Batch>>(model, theta_i, phi_i, first, n, sink, counters);
      },
      roughness_);
}

template <class Light, class Model>
void BatchTracer::trace_with(const Model& model, double theta_i, double phi_i,
                             std::uint64_t first, std::uint64_t n, const Sink& sink,
                             TracerCounters& counters) const {
  using OneLight = typename Light::template Rebind<double>;  // the same light, one photon
  auto pool_owner = std::make_unique<Pool>();
  Pool& pool = *pool_owner;
  auto done = std::make_unique<FinishedPhotons>();
  const Source source(settings_, theta_i, phi_i);
  const EllipseCrossSection& ellipse = config_.ellipse;
  const Eigen::Vector2d beam = ellipse.beam_direction(-direction_from_angles(theta_i, phi_i));
  const Batch iota = lane_index();
  life::LifeCounts<Batch> counts;

  // New photons into lanes [o, o + W), photons first, first + 1, ...: the
  // Source's streams and impact parameters and the life's start, a vector at
  // a time (a fixed incident direction). Lanes past the photons wanted are
  // free lanes (or the pool's spare ones): what is written there is never read.
  const bool vector_launch = source.fixed_direction();
  const Vec3 d_fixed = -direction_from_angles(theta_i, phi_i);
  const life::Vec3Of<Batch> d_lanes{Batch(d_fixed.x()), Batch(d_fixed.y()), Batch(d_fixed.z())};
  auto launch_vector = [&](int o, std::uint64_t first_photon) {
    const life::BitsOf<Batch> photon = life::BitsOf<Batch>(first_photon) + lane_photon_offsets();
    const auto lanes = source.template launch_lanes<Batch>(photon);
    Batch pv, pw;
    ellipse.entry_point_in_beam(beam, lanes.h, pv, pw);
    pool.store_state<Batch, Light, false>(o, life::start_photon<Light>(pv, pw, d_lanes, lanes.rng));
    Batch(phi_i).store_unaligned(pool.col[Pool::kPhiI] + o);
    photon.store_unaligned(pool.bits[Pool::kPhoton] + o);
  };
  // A new photon into lane i: the Source's launch, the life's start.
  auto launch = [&](int i, std::uint64_t photon) {
    const LaunchedPhoton p = source.launch(photon);
    const Vec3 d = -p.wi;
    const Point2 entry = ellipse.entry_point_in_beam(
        source.fixed_direction() ? beam : ellipse.beam_direction(d), p.h);
    pool.store_state(i, life::start_photon<OneLight>(entry, d, p.rng.core()));
    pool.col[Pool::kPhiI][i] = p.phi_i;
    pool.bits[Pool::kPhoton][i] = photon;
  };
  // The photon in lane i is done: to the block of finished photons.
  auto finish = [&](int i) {
    PhotonRandom rng(life::LaneRandom<double>(pool.bits[Pool::kS0][i], pool.bits[Pool::kS1][i],
                                              pool.bits[Pool::kS2][i], pool.bits[Pool::kS3][i]));
    const Vec3 d(pool.col[Pool::kDx][i], pool.col[Pool::kDy][i], pool.col[Pool::kDz][i]);
    const PhotonOutcome out = finished_outcome(
        model, static_cast<int>(pool.col[Pool::kCode][i]), d,
        static_cast<int>(pool.col[Pool::kSegments][i]), pool.col[Pool::kPath][i],
        pool.col[Pool::kWeight][i], rng);
    done->add(pool.bits[Pool::kPhoton][i], pool.col[Pool::kPhiI][i], out);
    if (done->full()) {
      exit_angles(*done);
      sink(*done);
      done->n = 0;
    }
  };

  const std::uint64_t end = first + n;
  std::uint64_t next = first;
  int n_active = 0;
  alignas(64) bool finished[kPoolLanes];  // lanes that finished this step
  while (true) {
    if (vector_launch) {
      while (n_active < kPoolLanes && next < end) {
        launch_vector(n_active, next);
        const int n = static_cast<int>(std::min<std::uint64_t>(
            std::min(W, kPoolLanes - n_active), end - next));
        n_active += n;
        next += n;
      }
    } else {
      while (n_active < kPoolLanes && next < end) launch(n_active++, next++);
    }
    if (n_active == 0) break;
    for (int o = 0; o < n_active; o += W) {
      const MaskOf<Batch> live = (iota + Batch(o)) < Batch(n_active);
      auto s = pool.load_state<Batch, Light>(o);
      life::step(config_, model, s, live, counts, kRoundsPerStep);
      pool.store_state(o, s);
      (live & (s.code != Batch(life::kAtBoundary))).store_aligned(finished + o);
    }
    // Hand over the finished photons, highest lane first: the last lane takes
    // a finished lane's slot, and every lane above it is already settled, so
    // the lane moved down is one still in flight. (The order photons reach
    // the sink does not matter: tallies are exact integer sums.)
    for (int o = (n_active - 1) / W * W; o >= 0; o -= W) {
      std::uint64_t lanes = 0;  // byte k: lane o + k finished (0 or 1)
      std::memcpy(&lanes, finished + o, W);
      while (lanes != 0) {
        const int top_byte = (63 - __builtin_clzll(lanes)) / 8;
        lanes &= ~(std::uint64_t{0xff} << (8 * top_byte));
        finish(o + top_byte);
        pool.move(o + top_byte, --n_active, Light::kPolarized);
      }
    }
  }
  if (done->n > 0) {
    exit_angles(*done);
    sink(*done);
  }
  counters.events += static_cast<long>(xsimd::hadd(counts.events));
  counters.normal_draws += static_cast<long>(xsimd::hadd(counts.normal_draws));
  counters.sampler_caps += static_cast<long>(xsimd::hadd(counts.sampler_caps));
}

}  // namespace fiberlab::sim
