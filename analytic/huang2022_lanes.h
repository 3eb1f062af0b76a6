// huang2022's paths (analytic/huang2022.h) for W points of its point set at
// once, one point per SIMD lane: the same transport as the scalar Paths of
// huang2022.cpp (which density() uses, with its stop-at-an-arrival hook),
// written without branches: every lane follows R, TT, TRT and the residual,
// and a mask says which of them the point's path reaches.
// bin_probabilities() and energies() use the float lanes (FloatTracer,
// xsimd::batch<float>, 16 lanes with AVX-512): float arithmetic in the
// quadrature's paths, about 1e-7 relative rounding per path, four orders
// below the quadrature's own error (~1e-3 of a lobe; test
// Huang2022.FloatLanesAreTheDoubleLanesToRounding measures the difference),
// with the paths' weights summed in double by the sinks. The double lanes
// (DoubleTracer, 8 lanes with AVX-512) are the same code on doubles: the
// test Huang2022.LanesEqualTheScalarPaths holds them to the scalar paths'
// energies and bins (any change of the transport must be made in both).
//
// Per point: the entry (Fiber::entry), the microfacet normal of each
// interface by Heitz 2018's VNDF map (common/ggx.h's sample_visible, here
// per lane), the Fresnel reflectance with its refraction cosine
// (common/fresnel.h's fresnel_reflectance, whose cos_t is Snell's refraction
// cosine, so a refraction costs no second square root), the ellipse's chord
// and the per-channel absorption exp(-sigma_a l) (not evaluated for
// sigma_a = 0).
#include <xsimd/xsimd.hpp>

#include "analytic/huang2022.h"

namespace fiberlab::analytic::huang_lanes {

inline constexpr int kMaxChannels = 8;  // Huang2022's constructor's limit
inline constexpr int kDims = 9;         // the point set's coordinates (huang2022.cpp)
// What trace() follows: bit p the exits of order p = 0, 1, 2, bit 3 the
// residual (every p >= 3); with kLedger also what the paths lose (masked,
// stopped), which bins do not need.
inline constexpr unsigned kAllOrders = 0b1111;
inline constexpr unsigned kLedger = 1u << 4;

template <class B>
struct V3T {
  B x, y, z;
};

// What W points' paths give, in units of the share `base` that trace() is
// given (the quadrature gives 1 per point and scales the sums by 1/N in
// double, huang2022.cpp): for p = 0, 1, 2 the exit directions,
// where an exit happened and its weight per channel (0 elsewhere); the
// residual's weight (p >= 3, before its spread); the weight removed by
// masking and by paths stopped on the wrong side; the light reaching the
// fiber.
template <class B>
struct ExitsT {
  using M = typename B::batch_bool_type;
  V3T<B> dir[3];
  M live[3];
  B w[3][kMaxChannels];
  B residual[kMaxChannels];
  B masked[kMaxChannels], stopped[kMaxChannels];
  B incident;
};

template <class B>
class TracerT {
 public:
  using M = typename B::batch_bool_type;
  using V3 = V3T<B>;
  using Exits = ExitsT<B>;
  using Batch = B;
  static constexpr int kWidth = static_cast<int>(B::size);

  // Whether the lanes implement every option of p (else huang2022.cpp uses
  // its scalar paths): a transport option added to the scalar Paths is
  // refused here until the lanes follow it and LanesEqualTheScalarPaths
  // covers it.
  static bool supports(const Huang2022Params& p);
  TracerT(const Huang2022Params& p, double theta_i, double phi_i);
  // u[k]: coordinate k of the W points (0 the entry angle, 1-2 / 3-4 / 5-6
  // the normals of interfaces 1 / 2 / 3); base: each point's share of the
  // beam (0 for a lane that holds no point; 1 gives Exits per unit share).
  // orders: kAllOrders's bits for the exits to follow, kLedger for the
  // losses. An order left out has no exit (live false, weight 0), and a path
  // ends where no order left to follow lies further along it (auto's points
  // beyond what a lobe needs, huang2022.cpp). Without kLedger, or without
  // every order, `masked` and `stopped` are not whole: bins only.
  void trace(const B* u, const B& base, Exits& out, unsigned orders = kAllOrders | kLedger) const;
  int channels() const { return C_; }

 private:
  struct Hit {
    B pv, pw;
    V3 n0, ns;
  };
  [[gnu::always_inline]] Hit hit(const B& pv, const B& pw) const;
  [[gnu::always_inline]] V3 normal(const Hit& h, double side, const V3& w, const B& u1, const B& u2) const;
  [[gnu::always_inline]] B leaving(const B& cos_in, const B& cos_out) const;
  [[gnu::always_inline]] B lambda_root(const B& c) const;
  void inside(const B* u, const Hit& from, const V3& d, const M& alive, const B* w, const B& t1,
              const B& cycles_weight, unsigned orders, Exits& out) const;

  double eta_, inv_eta_, alpha_, ct_, st_, irv2_, irw2_, rv_, rw_;
  double sigma_[kMaxChannels];
  int C_;
  HuangMasking masking_;
  bool mesonormal_flux_, cycles_residual_, cycles_trt_gate_, cycles_eval_;
  double wi_[3], gv_, gw_, cycles_scale_;
};

using FloatTracer = TracerT<xsimd::batch<float>>;   // the quadrature's
using DoubleTracer = TracerT<xsimd::batch<double>>; // the peer of the scalar paths (tests)
extern template class TracerT<xsimd::batch<float>>;
extern template class TracerT<xsimd::batch<double>>;

}  // namespace fiberlab::analytic::huang_lanes
