#pragma once
// Marschner, Jensen, Cammarano, Worley, Hanrahan 2003, "Light Scattering from
// Human Hair Fibers" (papers/marschner2003_light_scattering_from_hair.txt):
// the complete practical model of section 5, Eq. 9,
//
//   S = sum_{p=0..2} M_p(theta_h) N_p(eta'(eta, theta_d); phi) / cos^2(theta_d),
//
// returned as the density per d(theta_r) d(phi) of SPEC section 7:
//   density = S cos^2(theta_r).
//
// Frame (SPEC section 1): u the fiber tangent, v the major axis, w the minor
// axis; phi is measured from v about u; phi = phi_r - phi_i; phi_i is the
// incident azimuth (only the eccentricity approximation of section 5.2.3
// depends on it, through phi_h = phi_i + phi/2, and there only through
// cos(2 phi_h), which is single-valued under phi -> phi + 2 pi).
//
// Lobes: the model has R, TT, TRT (p = 0, 1, 2) only. Every p >= 3 is zero:
// that is the energy the model misses (SPEC section 8: 0.8% at theta_i = 0,
// 14% at theta_i = 85 deg for eta = 1.55).
//
// Parameters (Marschner2003Params below, angles in radians):
// - beta_long[p]: standard deviation of the Gaussian M_p (section 5.1) in the
//   variable the Gaussian is written in: theta_h (published) or 2 theta_h
//   (two_theta_h). beta must be > 0. There is no azimuthal width: the
//   published model has no azimuthal roughness other than the caustic width w_c.
// - alpha[p]: shift of theta_r for lobe p (SPEC section 7). Marschner's alpha_p
//   is a shift of theta_h, i.e. alpha[p] / 2; with two_theta_h the Gaussian is
//   g(beta; 2 theta_h - alpha[p]) = g(beta; theta_r + theta_i - alpha[p]).
// - exact_roots: solve Phi(p, h) = phi (Eq. 3) numerically, all roots, instead
//   of the cubic of Eq. 10.
// - absorption: Published = exp(-2 sigma_a' (1 + cos 2 gamma_t)) (section 4.3),
//   Chord = exp(-sigma_a' 2 cos gamma_t) (the chord of the unit circle).
// - eccentricity a (minor/major, SPEC section 2): eta*(phi_h) of section 5.2.3
//   replaces eta in N_TRT only (phi_h from the minor axis, see eta_star), and
//   there everywhere (eta', eta'', cos theta_t): the paper "simply pass[es]
//   the refractive index eta* to the code that computes N_TRT".
// - Caustic (section 5.2.2): k_g (glint scale), w_c (azimuthal width of the
//   caustic, radians), delta_eta (Delta eta', fade range past the merge),
//   delta_h_m (Delta h_M, caustic power limit). w_c == 0 (the default) means no
//   caustic smoothing: N_TRT is the exact Eq. 8 sum over roots, with its
//   integrable 1/sqrt singularities at the caustics. Table 1's typical values:
//   k_G 0.5 to 5, w_c 10 to 25 deg, Delta eta' 0.2 to 0.4, Delta h_M 0.5.
//   (With delta_h_m = 0 the caustic is removed and no glint is put back.)
//
// bin_probabilities() is overridden: the base class's 6 x 6 Gauss-Legendre
// rule per bin misses a Gaussian M narrower than a bin (beta = 0.1 deg in
// 2 deg bins: R 0.017 instead of 0.075) and the caustics; see the .cpp.
#include <memory>
#include <vector>

#include "analytic/longitudinal_lobes.h"
#include "analytic/model.h"

namespace fiberlab::analytic {

// The model's parameters (see above; its table, marschner2003_info() in
// marschner2003.cpp, binds `--set` keys to these fields). Lists are indexed
// by lobe p, the last entry for every larger p. The defaults are neutral
// values for code that builds the model directly (tests); the command
// line's are the table's.
struct Marschner2003Params {
  double eta = 1.55;
  std::vector<double> sigma_a{0.0, 0.0, 0.0};  // 1/R per channel
  std::vector<double> beta_long{0.0};          // per p
  std::vector<double> alpha{0.0};              // shift of theta_r per p
  Absorption absorption = Absorption::Published;
  int lobes = 4;                   // lobes 0..L-2 separately, lobe L-1 = every p >= L-1
  bool two_theta_h = false;        // longitudinal=theta_h|two_theta_h
  bool exact_roots = false;        // roots=cubic|exact
  double eccentricity = 1.0;       // a = minor/major
  double k_g = 0.5, w_c = 0.0, delta_eta = 0.0, delta_h_m = 0.0;  // caustics
};

// The Marschner 2003 model. Throws fiberlab::Error for parameters it cannot
// represent (beta_long <= 0, eta <= 1, a <= 0, w_c < 0, no channels).
std::unique_ptr<Model> make_marschner2003(const Marschner2003Params& params);
// The same model whose bin_probabilities() evaluates N's phi-bin integrals
// exactly at every theta_r quadrature node (no interpolation in theta_r):
// ~2x slower (90 x 180 bins, beta 5 deg), the reference the interpolation is
// tested against.
std::unique_ptr<Model> make_marschner2003_reference(const Marschner2003Params& params);

namespace marschner2003 {

// ---- Longitudinal scattering function M (section 5.1) ----------------------

// g(beta; x): unit-integral zero-mean Gaussian with standard deviation beta
// (longitudinal_lobes.h).
inline double g(double beta, double x) { return longitudinal::gaussian(beta, x); }

// M_p as published: g(beta; theta_h - alpha_theta_r / 2) (integrates to 2 over
// theta_r for small beta), or with two_theta_h g(beta; 2 theta_h - alpha_theta_r)
// (integrates to 1) (longitudinal_lobes.h).
inline double M_p(double beta, double alpha_theta_r, double theta_i, double theta_r, bool two_theta_h) {
  return longitudinal::gaussian_M_p(beta, alpha_theta_r, theta_i, theta_r, two_theta_h);
}

// ---- Bravais indices (Appendix B) ------------------------------------------

// eta'(theta) = sqrt(eta^2 - sin^2 theta) / cos theta: Snell's law holds for
// the projections into the normal plane with this index.
double eta_prime(double eta, double theta);
// eta''(theta) = eta^2 cos theta / sqrt(eta^2 - sin^2 theta).
double eta_double_prime(double eta, double theta);
// Generalized Fresnel F(eta', eta'', gamma) of Appendix B: s part with eta',
// p part with eta''. gamma is the projected angle of incidence. The refraction
// angle is the projected one, sin(gamma_t) = sin(gamma) / eta', for both
// polarizations (Bravais's law holds for the ray, whatever its polarization).
// The garbled text says only "eta' for the perpendicular component ... eta''
// for the parallel component"; with this reading F(eta', eta'', gamma) equals
// the 3D Fresnel reflectance at cos(i) = cos(theta) cos(gamma) exactly (tested),
// which is the paper's claim. Leaving the fiber, pass (1/eta', 1/eta'', gamma_t).
// Total internal reflection returns 1.
double F(double eta_p, double eta_pp, double gamma);

// ---- Paths through a circle (section 4.2, 5.2.1) ----------------------------

// Eq. 3: Phi(p, h) = 2 p gamma_t - 2 gamma_i + p pi, with sin gamma_i = h,
// sin gamma_t = h / eta'. Argument gamma_i (radians), not h.
double Phi(int p, double gamma_i, double eta_p);
// dPhi/dgamma_i of Eq. 3.
double dPhi_dgamma(int p, double gamma_i, double eta_p);
// Section 5.2.1: gamma_t ~ (3c/pi) gamma_i - (4c/pi^3) gamma_i^3, c = asin(1/eta').
double gamma_t_cubic(double gamma_i, double eta_p);
// Eq. 10: phi^(p, gamma_i) = (6pc/pi - 2) gamma_i - (8pc/pi^3) gamma_i^3 + p pi.
double Phi_cubic(int p, double gamma_i, double eta_p);
double dPhi_cubic_dgamma(int p, double gamma_i, double eta_p);

// Every gamma_i in [-pi/2, pi/2] whose exit angle is phi modulo 2 pi, from
// the cubic of Eq. 10 (closed form) or from Eq. 3 (Newton safeguarded by bisection on
// the monotonic pieces of Phi). Sorted ascending. h = sin(gamma_i).
std::vector<double> gamma_roots_cubic(int p, double phi, double eta_p);
std::vector<double> gamma_roots_exact(int p, double phi, double eta_p);

// ---- Attenuation (section 4.3) ----------------------------------------------

// T per internal segment; sigma_a_prime = sigma_a / cos(theta_t).
double T(double sigma_a_prime, double gamma_t, Absorption absorption);
// A(0, h) = F(eta', eta'', gamma_i);
// A(p, h) = (1 - F(eta', eta'', gamma_i))^2 F(1/eta', 1/eta'', gamma_t)^(p-1) T^p.
double A(int p, double gamma_i, double eta_p, double eta_pp, double sigma_a_prime,
         Absorption absorption);

// The 2D problem N is solved in: the Bravais indices at theta_d, cos(theta_t)
// for sigma_a' and the solver choices.
struct Projection {
  double eta = 1.55;     // the index the projection was made with
  double theta = 0.0;    // the inclination theta_d
  double eta_p = 1.55;   // eta'(eta, theta_d)
  double eta_pp = 1.55;  // eta''(eta, theta_d)
  double cos_theta_t = 1.0;  // sin(theta_t) = sin(theta_d) / eta
  bool exact_roots = false;
  Absorption absorption = Absorption::Published;
};
// eta is the (possibly eta*-modified) index; theta is theta_d.
Projection project(double eta, double theta, bool exact_roots, Absorption absorption);

// ---- Azimuthal scattering function N (Eq. 8) ---------------------------------

// N_p(p, phi) = sum_r A(p, h_r) / |2 dphi/dh (h_r)|, one value per sigma_a entry.
// dphi/dh is the derivative of the same phi used to find the roots (Eq. 10 with
// the cubic, Eq. 3 when exact), so that N integrates to (1/2) int A dh in both
// cases. A(p, h) always uses the exact gamma_t = asin(h / eta') (A is a
// function of h; the cubic only finds h). The fold (caustic) derivative zero
// is clamped (|dphi/dgamma| >= 1e-10) to keep the result finite.
void N_p(int p, double phi, const Projection& proj, const std::vector<double>& sigma_a,
         std::vector<double>& out);

// The TRT caustic (Eq. 4, section 5.2.2) of the phi function in use: for the
// exact Eq. 3, h_c^2 = (4 - eta'^2)/3; for the cubic of Eq. 10, the fold of the
// cubic (2 deg away in phi at eta' = 1.55), because only removing the
// singularity where the cubic puts it removes it. exists = false when
// eta' >= 2 (the caustics have merged).
struct Caustic {
  bool exists = false;
  double gamma_c = 0.0;    // gamma_i at the fold (> 0); h_c = sin(gamma_c)
  double h_c = 0.0;
  double phi_c = 0.0;      // exit angle of the fold, wrapped to [-pi, pi)
  double d2phi_dh2 = 0.0;  // at h_c
};
Caustic caustic(const Projection& proj);

struct CausticParams {
  double k_g = 0.5;        // glint scale factor
  double w_c = 0.0;        // azimuthal width of the caustic (radians)
  double delta_eta = 0.0;  // Delta eta': fade range past the merge
  double delta_h_m = 0.0;  // Delta h_M: caustic power limit
};
// N_TRT by the procedure of section 5.2.2 (with w_c == 0: N_p(2, phi)).
void N_TRT(double phi, const Projection& proj, const std::vector<double>& sigma_a,
           const CausticParams& caustic_params, std::vector<double>& out);

// Phi-bin integrals of N_p over n_phi uniform bins on [-pi, pi):
// out[j * C + c] = integral over bin j of N_p(phi) dphi = (1/2) int A(p, h) dh
// over the h whose exit angle (the phi function in use, Eq. 10 or Eq. 3)
// falls in bin j: exact, caustics included, with no root finding (the h
// range is split where the phi function crosses a bin edge and at its fold;
// Gauss-Legendre on each piece, cylinder::piece_nodes; A(p, h) by the
// shared cylinder::Attenuation, whose 3D Fresnel equals F above). For p = 2
// with caustic_params->w_c > 0 the procedure of section 5.2.2: the removal
// factor per h, and the two glint Gaussians' bin masses in closed form.
// Used by bin_probabilities() for circular fibers, and for R and TT of any
// fiber (eccentricity makes N_TRT depend on phi_h, and only N_TRT).
// proj.eta and proj.theta must be those it was made with (project()).
void N_p_bins(int p, const Projection& proj, const std::vector<double>& sigma_a,
              const CausticParams* caustic_params, int n_phi, std::vector<double>& out);

// ---- Eccentricity (section 5.2.3) -------------------------------------------

// eta*_1 = 2(eta-1)a^2 - eta + 2, eta*_2 = 2(eta-1)a^-2 - eta + 2,
// eta*(phi_h) = ((eta*_1 + eta*_2) + cos(2 phi_h)(eta*_1 - eta*_2)) / 2,
// exactly as printed, in the paper's phi_h. The printed text does not say from
// which axis its phi_h is measured, nor (Table 1: a "0.85 to 1") whether it
// matters. We settled it with a 2D ray trace of the ellipse (SPEC s2 shape,
// a = e = 0.85, eta 1.55, the test EccentricityMatchesEllipseRayTrace): light
// along the major axis v gives TRT caustics at +-0.23 deg (almost merged, an
// effective index near 2 = eta*_2 = 1.97), light along the minor axis w gives
// +-39.2 deg (a smaller index, towards eta*_1 = 1.25); the circle gives 18.6.
// So with a = minor/major the paper's phi_h = 0 is the minor axis: the model
// calls eta_star(eta, e, phi_h_spec - pi/2), phi_h_spec measured from v
// (SPEC s1). (Equivalently: a = major/minor with phi_h from the major axis.)
// The result is not clamped here; the model clamps it to eta* >= 1 + 1e-6
// (a < ~0.6 at eta = 1.55 gives eta* < 1, far outside the "mild
// eccentricity" the approximation is meant for).
double eta_star(double eta, double a, double phi_h);

}  // namespace marschner2003
}  // namespace fiberlab::analytic
