#pragma once
// Huang, Hullin, Hanika 2022, "A Microfacet-based Hair Scattering Model"
// (Computer Graphics Forum 41(4), EGSR 2022), the model behind Cycles'
// Principled Hair "Huang" (intern/cycles/kernel/closure/
// bsdf_principled_hair_huang.h), as a far-field scattering function of a
// fixed light (fiberlab's frame, SPEC s1 and s7).
//
// The fiber (paper section 3; Cycles' setup): an infinite cylinder whose
// cross-section is an ellipse, its surface covered by cuticle scales whose
// mean normal (the paper's mesonormal) is the ellipse's outward normal n0
// tilted along the fiber, and on that the rough surface of a GGX microfacet
// distribution about the mesonormal (isotropic roughness alpha). Every
// interface event is a single-scattering microfacet event: the normal m is
// one that the arriving direction sees (the GGX distribution of visible
// normals, VNDF), the light reflects with Fresnel F(eta, angle to m) and
// refracts with 1 - F (Snell about m), and Smith's masking of the leaving
// direction weights the result; paths that leave on the wrong side of the
// mesonormal or of the macro normal are not continued (the model's loss,
// together with the masking).
//
// In fiberlab's frame (SPEC s1, s2): the fiber axis is u; the ellipse has
// semi-axes r_v = 1/sqrt(e), r_w = sqrt(e), e = `eccentricity` = minor/major
// (Cycles' "aspect ratio" b <= 1; Cycles rescales its ellipse to the major
// axis 1 and normalises by its projected radius, which is the same model:
// the scattering function depends only on b, absorption lengths here are in
// units of the equivalent circle's radius, SPEC s2). The mesonormal is
// SPEC's tilted normal n_s = cos(tilt) n0 - sin(tilt) u, for hits from
// outside and inside alike: `tilt` > 0 is SPEC's scale_tilt > 0 (scales
// towards the root, R moves to theta_r < -theta_i). Cycles negates its
// user-facing tilt internally "to keep it consistent with principled hair"
// and builds the entry mesonormal with axis component sin(-tilt); its Y axis
// is the curve tangent (root -> tip), so Cycles' Huang "Tilt" input is this
// `tilt`.
//
// Frames: Cycles evaluates f(wi, wo) with the projected width and the
// integration range over h taken on its wi side (projected_area =
// cos theta(wi) dh), samples the first interfaces' microfacets from wi and
// evaluates the last interface towards wo. That is a light entering along
// -wi and leaving along wo: Cycles' wi plays our wi (the direction to the
// light), as the far field of a fixed light needs, and the prediction is
//   p(theta_r, phi) = S(wi, wr) cos(theta_r)   per d(theta_r) d(phi),
// with S normalised by the light's projected width W(wi) cos(theta_i).
//
// What follows the paper and what Cycles (equation numbers are not quoted:
// the paper was learnt through its Cycles implementation and abstract):
// Where the paper and Cycles' eval() differ, `form=paper` (the default)
// follows the paper's and Cycles' sampler's transport (every interface one
// microfacet event, light onto the arc by flux=mesonormal at the entry
// only); `form=cycles_eval` is Cycles' eval() (bsdf_hair_huang_eval_r,
// bsdf_hair_huang_eval_residual): it rescales the light of each inner chord
// by mesonormal cosine ratios (Paths::cycles_eval_chord_ratio), does not
// test TT light against the exit's normals, tests R's exit against the
// macro normal only, integrates over the impact parameters |h| <= 0.999 of
// the projected width only (normalised by the whole width), and sets its
// masking (correlated), flux (mesonormal) and p >= 3 formula
// (residual=cycles_eval). Not reproduced: eval_r's half
// vectors behind the mesonormal (its D is even in the cosine), TT where the
// exit's mesonormal faces away from the chord (eval still evaluates it),
// eval's zero for exits with tan(tilt) tan(theta_r) > 1 (a band within
// `tilt` of the axis), Cycles' roughness floor 1e-3 (bsdf_hair_huang_setup;
// here only in density()).
// - R (paper: the analytical R lobe for GGX): S_R = 1/(W cos theta_i)
//   integral over the lit arc of F(wi.h) D(h) G2(wi, wr) / 4 dl, h the half
//   vector, D and G about the mesonormal, the arc length dl of the ellipse;
//   density() evaluates this integral (paper; Cycles' eval_r).
// - TT, TRT (paper: the first interfaces' microfacets sampled from their
//   VNDF, the last interface evaluated towards wr; Cycles' eval_residual
//   does this with Monte Carlo normals inside a Simpson rule over the arc):
//   here the sampled normals are a fixed low-discrepancy point set (Halton,
//   bases 2, 3, 5, ...) mapped through Heitz 2018's VNDF map: a
//   deterministic quadrature of the same integral (same output every run),
//   not a random estimate. The chord inside is the ellipse's exact chord
//   (3D length, absorption exp(-sigma_a l)).
// - Masking: `masking=separable` G2 = G1(wi) G1(wo) per interface, the
//   paper's ground truth's "weight times G1" (and the simulator's
//   `masking: smith_g1`); `masking=correlated` the height-correlated
//   G2 = 1 / (1 + Lambda_i + Lambda_o) that Cycles' code uses (bsdf_G, and
//   bsdf_Go = G2 / G1(wi) for the sampled interfaces); `masking=none` G = 1
//   (a limit for tests).
// - p >= 3 (Cycles, not the paper's three lobes): the residual of Cycles'
//   sampler (sample_residual) after Chiang et al. 2016: the weight reflected
//   at the third interface times the geometric series
//   A_avg T_avg / (1 - A_avg (1 - T_avg)), A_avg = sqrt(A_t A_tr) (the two
//   chords' transmittances), T_avg = max(1e-5, (T_2 + T_3)/2) (Fresnel
//   transmittances at interfaces 2, 3), spread by d'Eon's M_p with
//   v = 4 alpha (Cycles' choice) about theta_r = -theta_i and uniformly in
//   phi. The third interface's reflection is also stopped when it leaves on
//   the wrong side of the mesonormal or the macro normal (as every event
//   here).
//   `residual=cycles_eval`: the residual of Cycles' eval() instead
//   (bsdf_hair_huang_eval_residual / _eval_trrt): at the second interface,
//   T1 R2^2 T_avg A^3 / (1 - A (1 - T_avg)), T_avg = max(1 - R2, 1e-5), T1 the
//   entry's Fresnel transmittance, R2 the second interface's reflectance, A
//   the first chord's transmittance, integrated uniformly over the arc angle
//   with weight (2/pi) / (cos theta_i W) (W Cycles' projected width 2r, the
//   major axis 1): no masking, no flux onto the arc, so its energy grows as
//   1/cos theta_i; the same M_p spread. On a smooth white circle it is
//   (1/(pi cos theta_i)) integral of (1 - F) F^2 dgamma, 3.0-3.5x the
//   sampler's (1/2) integral of (1 - F) F^2 cos gamma dgamma (tested). Cycles
//   drops it where the second interface's reflection leaves on the wrong side
//   and the exit direction lies in that reflection's refraction cone; here
//   it is kept for every exit direction (an over-count of that cone's share
//   of such paths); where the second interface's mesonormal faces away from
//   the arriving light (tilted fibers only) Cycles still samples a normal,
//   here the path ends without a residual. Cycles' eval()'s TT and TRT are
//   `form=cycles_eval` (which also sets this residual).
// - Per-lobe scales R, TT, TRT (`lobe_scale`, Cycles' modulation factors;
//   1 = the physical model); the residual is not scaled (as in Cycles).
// - Left out (Cycles): the GGX glass albedo correction (energy_scale, a
//   tabulated multiple-scattering compensation Cycles applies per
//   interface): not in the paper, not reproducible without its table; the
//   near field (a pixel's part of the width): fiberlab predicts far-field bins.
//
// Bin probabilities are the exact push-forward of the same quadrature: every
// point of the point set (h uniform over the projected width, the
// microfacet normals of up to three interfaces) is one path whose exit
// direction lands in one bin, with weight 1/N times its Fresnel, masking
// and absorption factors (where the fiber is mirror-symmetric about the
// plane of the light and the fiber axis, a circle or an ellipse lit along
// one of its axes, phi_i a multiple of 90 deg: half of it in that bin and
// half in the bin of its mirror image, relative azimuth -phi, the push-
// forward of the mirrored point set averaged in); the residual's weight is spread over the theta
// bins by the integral of its M_p over each bin (Gauss-Legendre, exact to
// the rule) and evenly over phi (for v = 4 alpha below 1e-6 the spread is
// sampled by two more coordinates of the point set). Each lobe's total is
// therefore the model's energy up to the quadrature error, and alpha = 0 is
// the smooth tilted elliptical fiber (with tilt 0 and e = 1 exactly the
// smooth cylinder of SPEC s7, orders p <= 2). The cost is linear in the
// points; bin_probabilities() and energies()
// trace 16 points at a time in float SIMD lanes (8 without AVX-512;
// huang2022_lanes.h, the same transport as the scalar paths that density()
// uses, in float arithmetic: ~1e-7 relative rounding per path, the weights
// summed in double), in 16 fixed blocks of the point set run on OpenMP
// threads (unless called inside a parallel region) and summed in block
// order: the same bits for any number of threads. The quadrature error of R, TT and TRT falls about 4x per 4x
// points (a push-forward of a fixed point set into bins converges like an
// estimate from as many independent paths, a little better; the error
// comes from the facet normals' coordinates, not from h: an
// Owen-scrambled Sobol' set, or 16 to 256 entry points h per sample of the
// normals, did no better at the same number of paths): at the
// atlas's grid (24 x 36 bins) and photon count (300k) the mean squared bin
// error over the simulated bin's variance is about N_photons / N_points
// times 0.10-0.26 for TT and TRT on mirror-symmetric fibers (every fiber of
// configs/atlas.yaml: `scripts/huang2022_quadrature_error.py
// configs/atlas.yaml --white`), about twice that without the mirror, and
// about the same on absorbing fibers in their simulations' own (smaller)
// standard errors. So `quadrature_points` is `auto` by default:
// per incident direction, a pilot of 2^18 points estimates the error and
// each lobe takes as many points (a multiple of 2^18, the pilot's included)
// as make its error a tenth of the standard error of a simulation of
// `quadrature_photons` photons (the simulation's own photons when the
// parameters come from one; huang2022.cpp says how). On configs/atlas.yaml
// (300k photons) a fiber's RMS bin error is then at most 0.052, 0.069,
// 0.089 and 0.009 standard errors for R, TT, TRT and p >= 3
// (`scripts/huang2022_quadrature_error.py configs/atlas.yaml --points auto
// --reference 33554432`), in the simulation's own standard errors, whose
// photons carry their attenuation (huang2022.cpp).
// A number instead fixes the points (fits do: a fixed set keeps the
// objective smooth in the parameters).
#include <memory>
#include <vector>

#include "analytic/model.h"
#include "common/fiber_frame.h"

namespace fiberlab::analytic {

enum class HuangMasking { Separable, Correlated, None };
// p >= 3: Cycles' sampler's residual (from the TRT path's third interface)
// or its eval()'s (from the second interface; see huang2022.cpp).
enum class HuangResidual { Sampler, CyclesEval };

// The transport: the paper's (and Cycles' sampler's), or that of Cycles'
// eval() as shipped (its inner mesonormal cosine ratios, its exit-side
// tests; see huang2022.cpp, Paths).
enum class HuangForm { Paper, CyclesEval };

// The evaluation of bin_probabilities() and energies() (Huang2022::set_paths).
enum class HuangPaths { FloatLanes, DoubleLanes, Scalar };

// Huang2022Params::quadrature_points = auto.
constexpr long kAutoQuadraturePoints = 0;

// The model's parameters (its table, huang2022_info() in huang2022.cpp, binds
// `--set` keys to these fields).
struct Huang2022Params {
  double eta = 1.55;                       // > 1
  std::vector<double> sigma_a{0.0};        // 1/R per channel, >= 0
  double roughness = 0.3;                  // GGX alpha in [0, 1]; 0 = smooth
  double tilt = 0.0;                       // radians, SPEC's scale_tilt sign
  double eccentricity = 1.0;               // minor/major in (0, 1]
  std::vector<double> lobe_scale{1.0, 1.0, 1.0};  // R, TT, TRT (>= 0)
  // Set before masking, flux and residual: `form=cycles_eval` in the table
  // also sets those to Cycles' eval()'s (correlated, mesonormal, cycles_eval).
  HuangForm form = HuangForm::Paper;
  HuangMasking masking = HuangMasking::Separable;
  // true (the paper, Cycles' eval() at the entry): the light reaching an
  // arc element is (wi.ns) dl, the flux onto the mesonormal; false: (wi.n0) dl, the
  // projected width's (every photon that meets the fiber scatters; Cycles'
  // sampler). They differ by up to tan(tilt) tan(theta_i) (see below).
  bool mesonormal_flux = true;
  HuangResidual residual = HuangResidual::Sampler;
  int lobes = 4;                           // 1..4 (p >= 3 is one residual lobe)
  // Points of the quadrature of bin_probabilities() and energies(): a number in
  // [1024, 2^30], or kAutoQuadraturePoints: as many as make the quadrature's
  // error a tenth of the standard error of a simulation of
  // `quadrature_photons` photons (see below).
  long quadrature_points = kAutoQuadraturePoints;
  double quadrature_photons = 300000.0;    // >= 1; the simulation's photons when read from one
};

// The energy a path integration gives, per channel c: lobe energies
// lobe[l * C + c], the weight removed by masking and by paths stopped on the
// wrong side, and the weight absorbed (orders p <= 2 exactly; for p >= 3 the
// residual's geometric series). With sigma_a = 0: sum(lobe) + masked +
// stopped = incident (every path's weight is one of these).
struct HuangEnergies {
  std::vector<double> lobe;
  std::vector<double> masked, stopped;
  double incident = 0.0;  // the light reaching the fiber (1 unless mesonormal_flux and tilt)
};

class Huang2022 : public Model {
 public:
  // Throws fiberlab::Error naming the parameter and its allowed range.
  explicit Huang2022(Huang2022Params params);
  std::string name() const override { return "huang2022"; }
  int lobes() const override { return params_.lobes; }
  // The paper's form: R by its integral over the arc (roughness floored at
  // 1e-3, as Cycles clamps it: a smooth lobe has no pointwise density), TT
  // and TRT with the last interface evaluated towards wr and the first ones
  // by the point set (2^16 points), the residual as M_p / (2 pi).
  void density(int lobe, double theta_i, double phi_i, double theta_r, double phi,
               std::vector<double>& out) const override;
  std::vector<double> bin_probabilities(const BinGrid& grid, double theta_i,
                                        double phi_i) const override;
  // Lobe energies and losses by the same point set as bin_probabilities().
  HuangEnergies energies(double theta_i, double phi_i) const;
  const Huang2022Params& params() const { return params_; }
  // Points of density()'s set for the interfaces before the last (tests).
  void set_density_points(long n) { density_points_ = n; }
  // Which paths bin_probabilities() and energies() take: the float SIMD
  // lanes (the default), the same lanes in double, or the scalar paths that
  // density() uses (huang2022_lanes.h): tests compare them. The scalar
  // paths serve a fixed quadrature_points only; auto's pilot runs in the
  // lanes' blocks, so with Scalar it takes the double lanes.
  void set_paths(HuangPaths paths) { paths_ = paths; }

 private:
  Huang2022Params params_;
  long density_points_ = 1L << 16;
  HuangPaths paths_ = HuangPaths::FloatLanes;
};

std::unique_ptr<Model> make_huang2022(const Huang2022Params& params);

}  // namespace fiberlab::analytic
