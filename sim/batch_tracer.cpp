#include "sim/batch_tracer.h"

#include <xsimd/xsimd.hpp>

#include <algorithm>
#include <cmath>
#include <memory>

#include "sim/exit_blur.h"
#include "sim/microfacet_normal.h"
#include "sim/source.h"

namespace fiberlab::sim {

namespace {

using Batch = xsimd::batch<double>;
using UBatch = xsimd::batch<std::uint64_t>;
using Mask = Batch::batch_bool_type;
using UMask = UBatch::batch_bool_type;
constexpr int W = static_cast<int>(Batch::size);
constexpr int kPoolLanes = 32 * W;  // photons in flight per thread

// What a lane's photon does next (kept as a double per lane).
enum LaneCode : int { kAtBoundary = 0, kExited = 1, kTruncated = 2, kTravel = 3 };

UMask to_umask(const Mask& m) {
  return xsimd::bitwise_cast<UBatch>(xsimd::select(m, Batch(1.0), Batch(0.0))) != UBatch(0);
}

Batch lane_index() {
  alignas(64) double idx[W];
  for (int i = 0; i < W; ++i) idx[i] = i;
  return Batch::load_aligned(idx);
}

// Counts lanes over many masks without leaving the vector unit; total() at the end.
class LaneCounter {
 public:
  void add(const Mask& m) { sum_ = sum_ + xsimd::select(m, Batch(1.0), Batch(0.0)); }
  long total() const { return static_cast<long>(xsimd::hadd(sum_)); }

 private:
  Batch sum_ = Batch(0.0);
};

}  // namespace

// The pool of photons in flight, structure of arrays.
struct BatchTracer::Lanes {
  alignas(64) double px[kPoolLanes], py[kPoolLanes];             // boundary point (v, w)
  alignas(64) double dx[kPoolLanes], dy[kPoolLanes], dz[kPoolLanes];  // direction
  alignas(64) double inside[kPoolLanes];       // 1 inside the fiber, 0 outside
  alignas(64) double path[kPoolLanes];         // internal 3D path length
  alignas(64) double segments[kPoolLanes];
  alignas(64) double events_here[kPoolLanes];  // events at the current point
  alignas(64) double code[kPoolLanes];         // LaneCode
  alignas(64) double phi_i[kPoolLanes];
  alignas(64) std::uint64_t photon[kPoolLanes];
  alignas(64) std::uint64_t s0[kPoolLanes], s1[kPoolLanes], s2[kPoolLanes], s3[kPoolLanes];
  alignas(64) double spare[kPoolLanes], has_spare[kPoolLanes];
  alignas(64) double tries[kPoolLanes];   // candidate normals drawn for the pending event
  LaneCounter events, normal_draws, sampler_caps;  // for TracerCounters

  void move(int to, int from) {
    px[to] = px[from]; py[to] = py[from];
    dx[to] = dx[from]; dy[to] = dy[from]; dz[to] = dz[from];
    inside[to] = inside[from]; path[to] = path[from]; segments[to] = segments[from];
    events_here[to] = events_here[from]; code[to] = code[from]; phi_i[to] = phi_i[from];
    photon[to] = photon[from];
    s0[to] = s0[from]; s1[to] = s1[from]; s2[to] = s2[from]; s3[to] = s3[from];
    spare[to] = spare[from]; has_spare[to] = has_spare[from];
    tries[to] = tries[from];
  }
  RandomState rng_state(int i) const {
    return {{s0[i], s1[i], s2[i], s3[i]}, spare[i], has_spare[i] != 0.0};
  }
  void set_rng_state(int i, const RandomState& st) {
    s0[i] = st.s[0]; s1[i] = st.s[1]; s2[i] = st.s[2]; s3[i] = st.s[3];
    spare[i] = st.spare; has_spare[i] = st.has_spare ? 1.0 : 0.0;
  }
};

namespace {

// W photons' random streams side by side: the same xoshiro256** and
// Box-Muller as PhotonRandom, advancing only the lanes in a mask, so each
// photon consumes its own stream in the same order as in Tracer.
class LaneRandom {
 public:
  LaneRandom(const BatchTracer::Lanes& l, int o)
      : s0_(UBatch::load_aligned(l.s0 + o)), s1_(UBatch::load_aligned(l.s1 + o)),
        s2_(UBatch::load_aligned(l.s2 + o)), s3_(UBatch::load_aligned(l.s3 + o)),
        spare_(Batch::load_aligned(l.spare + o)),
        has_spare_(Batch::load_aligned(l.has_spare + o) != Batch(0.0)) {}

  // Fresh streams: PhotonRandom(key, photon) for W photons at once.
  LaneRandom(std::uint64_t key, const UBatch& photon) : spare_(0.0), has_spare_(Batch(0.0) != Batch(0.0)) {
    UBatch x = splitmix(UBatch(key) ^ photon);
    s0_ = x = splitmix(x);
    s1_ = x = splitmix(x);
    s2_ = x = splitmix(x);
    s3_ = splitmix(x);
  }

  // Stores lanes [o, o + n) (n <= W), at any offset.
  void store_unaligned(BatchTracer::Lanes& l, int o, int n) const {
    alignas(64) std::uint64_t a0[W], a1[W], a2[W], a3[W];
    s0_.store_aligned(a0);
    s1_.store_aligned(a1);
    s2_.store_aligned(a2);
    s3_.store_aligned(a3);
    for (int i = 0; i < n; ++i) {
      l.s0[o + i] = a0[i];
      l.s1[o + i] = a1[i];
      l.s2[o + i] = a2[i];
      l.s3[o + i] = a3[i];
      l.spare[o + i] = 0.0;
      l.has_spare[o + i] = 0.0;
    }
  }

  void store(BatchTracer::Lanes& l, int o) const {
    s0_.store_aligned(l.s0 + o);
    s1_.store_aligned(l.s1 + o);
    s2_.store_aligned(l.s2 + o);
    s3_.store_aligned(l.s3 + o);
    spare_.store_aligned(l.spare + o);
    xsimd::select(has_spare_, Batch(1.0), Batch(0.0)).store_aligned(l.has_spare + o);
  }

  Batch uniform(const Mask& m) { return to_unit(next(m)); }
  Batch uniform_open0(const Mask& m) { return to_unit(next(m)) + Batch(0x1.0p-53); }

  Batch normal(const Mask& m) {
    const Mask use_spare = m & has_spare_;
    const Mask generate = m & !has_spare_;
    if (!xsimd::any(generate)) {
      has_spare_ = has_spare_ & !m;
      return spare_;
    }
    const Batch r = xsimd::sqrt(Batch(-2.0) * xsimd::log(uniform_open0(generate)));
    const Batch a = Batch(6.283185307179586) * uniform(generate);
    const auto [sn, cs] = xsimd::sincos(a);
    const Batch out = xsimd::select(use_spare, spare_, r * cs);
    spare_ = xsimd::select(generate, r * sn, spare_);
    has_spare_ = (has_spare_ & !m) | generate;
    return out;
  }

  // normal(first) then normal(second) lane by lane, with one Box-Muller
  // generation instead of two: a lane that draws both uses its spare for one
  // and generates the other, so it generates exactly once, and a lane that
  // draws one generates only without a spare. Each lane's stream is consumed
  // as by two calls of normal(). Lanes in `second` only must have made no
  // other draw since `first` (true for the sampler's dl, da).
  std::pair<Batch, Batch> normal_pair(const Mask& first, const Mask& second) {
    const Mask gen_first = first & !has_spare_;
    const Mask spare_after_first = (has_spare_ & !first) | gen_first;
    const Mask gen_second = second & !spare_after_first;
    const Mask generate = gen_first | gen_second;
    Batch cs(0.0), sn(0.0);
    if (xsimd::any(generate)) {
      const Batch r = xsimd::sqrt(Batch(-2.0) * xsimd::log(uniform_open0(generate)));
      const auto [s, c] = xsimd::sincos(Batch(6.283185307179586) * uniform(generate));
      cs = r * c;
      sn = r * s;
    }
    // First draw: spare, or the cosine of a new pair (sine kept).
    const Batch a = xsimd::select(gen_first, cs, spare_);
    // Second draw: spare (old or just made), or the cosine of a new pair.
    const Batch spare_for_second = xsimd::select(gen_first, sn, spare_);
    const Batch b = xsimd::select(gen_second, cs, spare_for_second);
    // What is left as spare: the sine of a pair generated for the second
    // draw, nothing if the second draw used a spare, otherwise unchanged.
    spare_ = xsimd::select(gen_second, sn, xsimd::select(gen_first, sn, spare_));
    const Mask used_second_spare = second & spare_after_first;
    has_spare_ = (spare_after_first & !used_second_spare) | gen_second;
    return {a, b};
  }

  // sigma * |x| of a Normal weighted by |x| (Rayleigh), then a random sign.
  Batch signed_rayleigh(double sigma, const Mask& m) {
    if (!xsimd::any(m)) return Batch(0.0);
    const Batch r = Batch(sigma) * xsimd::sqrt(Batch(-2.0) * xsimd::log(uniform_open0(m)));
    return xsimd::select(uniform(m) < Batch(0.5), -r, r);
  }

 private:
  static UBatch rotl(const UBatch& x, int k) { return (x << k) | (x >> (64 - k)); }
  static UBatch splitmix(UBatch z) {  // PhotonRandom::splitmix, lane by lane
    z = z + UBatch(0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * UBatch(0xbf58476d1ce4e5b9ULL);
    z = (z ^ (z >> 27)) * UBatch(0x94d049bb133111ebULL);
    return z ^ (z >> 31);
  }
  static Batch to_unit(const UBatch& x) {
    return xsimd::to_float(xsimd::bitwise_cast<xsimd::batch<std::int64_t>>(x >> 11)) *
           Batch(0x1.0p-53);
  }
  UBatch next(const Mask& m) {
    const UMask um = to_umask(m);
    const UBatch x5 = (s1_ << 2) + s1_;
    const UBatch r7 = rotl(x5, 7);
    const UBatch result = (r7 << 3) + r7;
    const UBatch t = s1_ << 17;
    UBatch n2 = s2_ ^ s0_;
    UBatch n3 = s3_ ^ s1_;
    const UBatch n1 = s1_ ^ n2;
    const UBatch n0 = s0_ ^ n3;
    n2 = n2 ^ t;
    n3 = rotl(n3, 45);
    s0_ = xsimd::select(um, n0, s0_);
    s1_ = xsimd::select(um, n1, s1_);
    s2_ = xsimd::select(um, n2, s2_);
    s3_ = xsimd::select(um, n3, s3_);
    return result;
  }

  UBatch s0_, s1_, s2_, s3_;
  Batch spare_;
  Mask has_spare_;
};

struct Vec3B {
  Batch x, y, z;
  Batch dot(const Vec3B& o) const { return x * o.x + y * o.y + z * o.z; }
  Vec3B normalized() const {
    const Batch inv = Batch(1.0) / xsimd::sqrt(dot(*this));
    return {x * inv, y * inv, z * inv};
  }
};
Vec3B operator*(const Batch& s, const Vec3B& v) { return {s * v.x, s * v.y, s * v.z}; }
Vec3B operator+(const Vec3B& a, const Vec3B& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Vec3B select(const Mask& m, const Vec3B& a, const Vec3B& b) {
  return {xsimd::select(m, a.x, b.x), xsimd::select(m, a.y, b.y), xsimd::select(m, a.z, b.z)};
}

// The gaussian microfacet normal, both samplers of microfacet_normal.cpp
// (which explains them), for the lanes in `live`. A group of lanes is only
// as fast as its slowest, so each call draws at most kRoundsPerCall
// candidates per lane: lanes still without a normal are left out of this
// event (not `ready`) and continue drawing from their own stream at the next
// call, with their count of candidates so far in `tries`. Lanes that reach
// the cap are returned in `failed` (truncated, as in Tracer).
constexpr int kRoundsPerCall = 2;

Vec3B gaussian_normals(const Vec3B& d, const Vec3B& f, double beta_long, double beta_azim,
                       double far_tail_threshold, const Mask& live, LaneRandom& rng,
                       Batch& tries, Mask& ready, Mask& failed, LaneCounter& draws) {
  constexpr double kSqrt2OverPi = 0.7978845608028654;
  const Batch sin_n = f.x, cos_n = xsimd::sqrt(f.y * f.y + f.z * f.z);
  const Batch inv = Batch(1.0) / cos_n;
  const Batch pv = f.y * inv, pw = f.z * inv;
  const Batch d_dot_n = d.dot(f);
  const Batch c = xsimd::max(Batch(0.0), -d_dot_n);
  const Batch w_long(beta_long * kSqrt2OverPi), w_azim(beta_azim * kSqrt2OverPi);
  // Sampler (c), the far tail, where n_f faces away by eps >= kFarTailSigmas b.
  const Mask far = d_dot_n >= Batch(far_tail_threshold);
  const double b = std::max(beta_long, beta_azim);
  const Batch rho0 = xsimd::asin(xsimd::min(Batch(1.0), d_dot_n)) / Batch(b);
  const Mask envelope = (c < Batch(0.5)) & !far;
  const Batch w_total = c + w_long + w_azim;
  failed = live & envelope & (w_total <= Batch(0.0));
  ready = live & Mask(false);
  Mask pending = live & !failed;
  Vec3B m{Batch(0.0), Batch(0.0), Batch(0.0)};
  for (int k = 0; k < kRoundsPerCall && xsimd::any(pending); ++k) {
    draws.add(pending);
    tries = tries + xsimd::select(pending, Batch(1.0), Batch(0.0));
    const Mask near = pending & !far, far_p = pending & far;
    const Batch pick = w_total * rng.uniform(near & envelope);
    const Mask first = envelope & (pick < c);
    const Mask second = envelope & !first & (pick < c + w_long);
    const Mask third = envelope & !first & !second;
    // Per lane: dl then da, each a normal or (envelope) a signed Rayleigh.
    const Batch dl_rayleigh = rng.signed_rayleigh(beta_long, near & second);
    const auto [n_long, n_azim] = rng.normal_pair(near & !second, near & !third);
    const Batch da_rayleigh = rng.signed_rayleigh(beta_azim, near & third);
    Batch dl = xsimd::select(second, dl_rayleigh, Batch(beta_long) * n_long);
    Batch da = xsimd::select(third, da_rayleigh, Batch(beta_azim) * n_azim);
    Batch bound = xsimd::select(envelope, c + xsimd::abs(dl) + xsimd::abs(da), Batch(1.0));
    Mask radial_ok = far_p;
    if (xsimd::any(far_p)) {  // far_tail_normal in microfacet_normal.cpp, lane by lane
      const Batch u1 = rng.uniform_open0(far_p), u2 = rng.uniform_open0(far_p);
      const Batch w = -xsimd::log(u1 * u2);  // Gamma(2, 1)
      const Batch y = Batch(2.0) * w / (xsimd::sqrt(rho0 * rho0 + Batch(2.0) * w) + rho0);
      radial_ok = far_p & (rng.uniform(far_p) * w < rho0 * y);
      const Batch psi = Batch(6.283185307179586) * rng.uniform(radial_ok);
      const auto [sp, cp] = xsimd::sincos(psi);
      const Batch rho = rho0 + y;
      dl = xsimd::select(far, Batch(beta_long) * rho * cp, dl);
      da = xsimd::select(far, Batch(beta_azim) * rho * sp, da);
      bound = xsimd::select(far, Batch(b) * y, bound);
    }
    const auto [sl, cl] = xsimd::sincos(dl);
    const Batch st = sin_n * cl + cos_n * sl, ct = cos_n * cl - sin_n * sl;
    const auto [sa, ca] = xsimd::sincos(da);
    const Vec3B candidate{st, ct * (pv * ca - pw * sa), ct * (pv * sa + pw * ca)};
    const Batch visible = -d.dot(candidate);
    const Mask facing = (near | radial_ok) & (visible > Batch(0.0));
    const Mask accepted = facing & (rng.uniform(facing) * bound < visible);
    m = select(accepted, candidate, m);
    ready = ready | accepted;
    pending = pending & !accepted;
    failed = failed | (pending & (tries >= Batch(Tracer::kMaxNormalTries)));
    pending = pending & !failed;
  }
  tries = xsimd::select(ready | failed, Batch(0.0), tries);
  return m;
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
    : settings_(s),
      model_(Tracer::effective_model(s.roughness)),
      ellipse_(s.fiber.eccentricity),
      cos_tilt_(std::cos(s.fiber.scale_tilt)),
      sin_tilt_(std::sin(s.fiber.scale_tilt)) {}

// `beam` is the entry geometry of the source's fixed direction (unused when
// each photon has its own).
void BatchTracer::launch(Lanes& l, int i, const Source& source, const Eigen::Vector2d& beam,
                         std::uint64_t photon) const {
  const LaunchedPhoton p = source.launch(photon);
  const Vec3 d = -p.wi;
  const Point2 entry = ellipse_.entry_point_in_beam(
      source.fixed_direction() ? beam : ellipse_.beam_direction(d), p.h);
  l.px[i] = entry.x();
  l.py[i] = entry.y();
  l.dx[i] = d.x();
  l.dy[i] = d.y();
  l.dz[i] = d.z();
  l.inside[i] = 0.0;
  l.path[i] = 0.0;
  l.segments[i] = 0.0;
  l.events_here[i] = 0.0;
  l.tries[i] = 0.0;
  l.code[i] = kAtBoundary;
  l.phi_i[i] = p.phi_i;
  l.photon[i] = photon;
  l.set_rng_state(i, p.rng.state());
}

// launch() for `n` <= W photons of a fixed incident direction d (beam
// geometry g) into lanes [o, o + n), their streams seeded and their entry
// points computed side by side.
void BatchTracer::launch_group(Lanes& l, int o, int n, std::uint64_t photon0, const Source& source,
                               const Vec3& d, const Eigen::Vector2d& g, double phi_i) const {
  alignas(64) std::uint64_t index[W];
  for (int i = 0; i < W; ++i) index[i] = photon0 + static_cast<std::uint64_t>(i);
  LaneRandom rng(source.stream_key(), UBatch::load_aligned(index));
  alignas(64) double hs[W];  // the Source's h (stratified or not) from each lane's draw
  rng.uniform(Batch(0.0) == Batch(0.0)).store_aligned(hs);
  for (int i = 0; i < W; ++i) hs[i] = source.impact_parameter(index[i], hs[i]);
  const Batch h = Batch::load_aligned(hs);
  const Batch root = xsimd::sqrt(xsimd::max(Batch(0.0), Batch(1.0) - h * h));
  // EllipseCrossSection::entry_point_in_beam: q = h g_perp - sqrt(1 - h^2) g.
  const Batch px = Batch(ellipse_.r_v()) * (h * Batch(-g.y()) - root * Batch(g.x()));
  const Batch py = Batch(ellipse_.r_w()) * (h * Batch(g.x()) - root * Batch(g.y()));
  alignas(64) double ax[W], ay[W];
  px.store_aligned(ax);
  py.store_aligned(ay);
  for (int i = 0; i < n; ++i) {
    const int lane = o + i;
    l.px[lane] = ax[i];
    l.py[lane] = ay[i];
    l.dx[lane] = d.x();
    l.dy[lane] = d.y();
    l.dz[lane] = d.z();
    l.inside[lane] = l.path[lane] = l.segments[lane] = l.events_here[lane] = l.tries[lane] = 0.0;
    l.code[lane] = kAtBoundary;
    l.phi_i[lane] = phi_i;
    l.photon[lane] = index[i];
  }
  rng.store_unaligned(l, o, n);
}

// One interface event for every photon in flight (SPEC section 3): the
// vectorised ScalarLight::interact with the normal models of Tracer.
void BatchTracer::interface_events(Lanes& l, int n_active) const {
  const double eta = settings_.fiber.eta;
  const RoughnessModel model = model_;
  const double beta_long = settings_.roughness.beta_long.front();
  const double beta_azim = settings_.roughness.beta_azim.front();
  const double far_tail_threshold = sim::far_tail_threshold(std::max(beta_long, beta_azim));
  const Batch iota = lane_index();
  for (int o = 0; o < n_active; o += W) {
    const Mask live = (iota + Batch(o)) < Batch(n_active);
    LaneRandom rng(l, o);
    const Batch px = Batch::load_aligned(l.px + o), py = Batch::load_aligned(l.py + o);
    Vec3B d{Batch::load_aligned(l.dx + o), Batch::load_aligned(l.dy + o),
            Batch::load_aligned(l.dz + o)};
    const Mask inside = Batch::load_aligned(l.inside + o) != Batch(0.0);
    // Untilted outward normal n0 and the tilted normal n_s (SPEC section 2).
    const Batch nv = px * Batch(1.0 / (ellipse_.r_v() * ellipse_.r_v()));
    const Batch nw = py * Batch(1.0 / (ellipse_.r_w() * ellipse_.r_w()));
    const Batch inv = Batch(1.0) / xsimd::sqrt(nv * nv + nw * nw);
    const Vec3B n0{Batch(0.0), nv * inv, nw * inv};
    const Batch side = xsimd::select(inside, Batch(-1.0), Batch(1.0));
    const Vec3B facing{side * Batch(-sin_tilt_), side * Batch(cos_tilt_) * n0.y,
                       side * Batch(cos_tilt_) * n0.z};
    Mask failed = live & Mask(false), ready = live;
    Vec3B m;
    if (model == RoughnessModel::Gaussian) {
      Batch tries = Batch::load_aligned(l.tries + o);
      m = gaussian_normals(d, facing, beta_long, beta_azim, far_tail_threshold, live, rng, tries,
                           ready, failed, l.normal_draws);
      tries.store_aligned(l.tries + o);
      l.sampler_caps.add(failed);
    } else {
      m = select(d.dot(facing) < Batch(0.0), facing, side * n0);
    }
    // Fresnel and the choice between reflection and refraction, for the
    // lanes that have their normal.
    const Mask act = ready & !failed;
    const Batch cos_i = xsimd::min(Batch(1.0), xsimd::max(Batch(0.0), -d.dot(m)));
    const Batch eta_rel = xsimd::select(inside, Batch(1.0 / eta), Batch(eta));
    const Batch ratio = xsimd::select(inside, Batch(eta), Batch(1.0 / eta));
    const Batch sin2_t = ratio * ratio * (Batch(1.0) - cos_i * cos_i);
    const Mask tir = sin2_t >= Batch(1.0);
    const Batch cos_t = xsimd::sqrt(xsimd::max(Batch(0.0), Batch(1.0) - sin2_t));
    const Batch r_s = (cos_i - eta_rel * cos_t) / (cos_i + eta_rel * cos_t);
    const Batch r_p = (eta_rel * cos_i - cos_t) / (eta_rel * cos_i + cos_t);
    const Batch F = Batch(0.5) * (r_s * r_s + r_p * r_p);
    const Mask reflect = tir | (rng.uniform(act & !tir) < F);
    // reflect() or refract() of interface_event.h, only the chosen one normalised:
    // d' = a d + b m with (a, b) = (1, 2 cos_i) or (ratio, ratio cos_i - cos_t).
    const Batch a = xsimd::select(reflect, Batch(1.0), ratio);
    const Batch b = xsimd::select(reflect, Batch(2.0) * cos_i, ratio * cos_i - cos_t);
    d = select(act, (a * d + b * m).normalized(), d);
    const Mask flip = act & !reflect;
    const Mask now_inside = (flip & (!inside)) | ((!flip) & inside);
    // Consistency rule, judged with the untilted normal.
    const Batch dn = d.dot(n0);
    const Mask consistent = (now_inside & (dn < Batch(0.0))) | ((!now_inside) & (dn > Batch(0.0)));
    Batch code = xsimd::select(consistent, xsimd::select(now_inside, Batch(kTravel), Batch(kExited)),
                               Batch(kAtBoundary));
    code = xsimd::select(failed, Batch(kTruncated), code);
    code = xsimd::select(act | failed, code, Batch::load_aligned(l.code + o));
    d.x.store_aligned(l.dx + o);
    d.y.store_aligned(l.dy + o);
    d.z.store_aligned(l.dz + o);
    xsimd::select(now_inside, Batch(1.0), Batch(0.0)).store_aligned(l.inside + o);
    const Batch events_here =
        Batch::load_aligned(l.events_here + o) + xsimd::select(act, Batch(1.0), Batch(0.0));
    events_here.store_aligned(l.events_here + o);
    // Still undecided after max_events_per_point events at this point: truncated.
    const Mask stuck = act & (!consistent) & (events_here >= Batch(settings_.max_events_per_point));
    xsimd::select(stuck, Batch(kTruncated), code).store_aligned(l.code + o);
    rng.store(l, o);
    l.events.add(act);
  }
}

// One internal segment for the photons about to cross the fiber (SPEC
// sections 2 and 4): the vector form of EllipseCrossSection's
// distance_to_boundary (the far root t = -B/A) and advance.
void BatchTracer::travel(Lanes& l, int n_active) const {
  const Batch inv_rv2(1.0 / (ellipse_.r_v() * ellipse_.r_v()));
  const Batch inv_rw2(1.0 / (ellipse_.r_w() * ellipse_.r_w()));
  for (int o = 0; o < n_active; o += W) {
    Batch code = Batch::load_aligned(l.code + o);
    // A photon that did not leave at the boundary ending its last allowed
    // segment is truncated (SPEC section 5).
    const Mask at_limit = (code == Batch(kTravel)) &
                          (Batch::load_aligned(l.segments + o) >= Batch(settings_.max_segments));
    code = xsimd::select(at_limit, Batch(kTruncated), code);
    const Mask go = code == Batch(kTravel);
    if (!xsimd::any(go)) {
      code.store_aligned(l.code + o);
      continue;
    }
    const Batch px = Batch::load_aligned(l.px + o), py = Batch::load_aligned(l.py + o);
    const Batch dy = Batch::load_aligned(l.dy + o), dz = Batch::load_aligned(l.dz + o);
    const Batch a = dy * dy * inv_rv2 + dz * dz * inv_rw2;
    const Batch b = Batch(2.0) * (px * dy * inv_rv2 + py * dz * inv_rw2);
    const Mask along_axis = go & (a <= Batch(0.0));  // guided for ever
    const Batch t = xsimd::select(go & !along_axis, xsimd::max(Batch(0.0), -b / a), Batch(0.0));
    const Batch qx = px + t * dy, qy = py + t * dz;
    const Batch s = Batch(1.0) / xsimd::sqrt(qx * qx * inv_rv2 + qy * qy * inv_rw2);
    const Mask moved = go & !along_axis;
    xsimd::select(moved, qx * s, px).store_aligned(l.px + o);
    xsimd::select(moved, qy * s, py).store_aligned(l.py + o);
    (Batch::load_aligned(l.path + o) + t).store_aligned(l.path + o);
    (Batch::load_aligned(l.segments + o) + xsimd::select(moved, Batch(1.0), Batch(0.0)))
        .store_aligned(l.segments + o);
    xsimd::select(moved, Batch(0.0), Batch::load_aligned(l.events_here + o))
        .store_aligned(l.events_here + o);
    xsimd::select(moved, Batch(kAtBoundary), xsimd::select(along_axis, Batch(kTruncated), code))
        .store_aligned(l.code + o);
  }
}

void BatchTracer::trace(double theta_i, double phi_i, std::uint64_t first, std::uint64_t n,
                        const Sink& sink, TracerCounters& counters) const {
  auto lanes = std::make_unique<Lanes>();
  Lanes& l = *lanes;
  const std::uint64_t end = first + n;
  std::uint64_t next = first;
  int n_active = 0;
  const bool blur = model_ == RoughnessModel::ExitBlur;
  const ExitBlur exit_blur(settings_.roughness);

  auto done = std::make_unique<FinishedPhotons>();
  auto finish = [&](int i, PhotonFate fate) {
    PhotonOutcome out;
    out.fate = fate;
    out.segments = static_cast<int>(l.segments[i]);
    out.path_length = l.path[i];
    if (fate == PhotonFate::Exited) {
      out.direction = Vec3(l.dx[i], l.dy[i], l.dz[i]);
      if (blur) {
        PhotonRandom rng(l.rng_state(i));
        out.direction = exit_blur.apply(out.direction, out.segments, rng);
      }
    }
    done->add(l.photon[i], l.phi_i[i], out);  // theta, phi follow for the whole block
    if (done->full()) {
      exit_angles(*done);
      sink(*done);
      done->n = 0;
    }
  };

  const Source source(settings_, theta_i, phi_i);
  const Vec3 d0 = -direction_from_angles(theta_i, phi_i);
  const Eigen::Vector2d beam = ellipse_.beam_direction(d0);
  while (true) {
    if (source.fixed_direction()) {
      while (n_active < kPoolLanes && next < end) {
        const int n = static_cast<int>(std::min<std::uint64_t>(
            std::min(W, kPoolLanes - n_active), end - next));
        launch_group(l, n_active, n, next, source, d0, beam, phi_i);
        n_active += n;
        next += n;
      }
    } else {
      while (n_active < kPoolLanes && next < end) launch(l, n_active++, source, beam, next++);
    }
    if (n_active == 0) break;
    interface_events(l, n_active);
    travel(l, n_active);
    for (int i = 0; i < n_active;) {  // report finished photons; the last lane takes the slot
      const int code = static_cast<int>(l.code[i]);
      if (code == kExited || code == kTruncated) {
        finish(i, code == kExited ? PhotonFate::Exited : PhotonFate::Truncated);
        l.move(i, --n_active);
      } else {
        ++i;
      }
    }
  }
  if (done->n > 0) {
    exit_angles(*done);
    sink(*done);
  }
  counters.events += l.events.total();
  counters.normal_draws += l.normal_draws.total();
  counters.sampler_caps += l.sampler_caps.total();
}

}  // namespace fiberlab::sim
