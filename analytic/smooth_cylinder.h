#pragma once
// The exact smooth circular cylinder (SPEC section 7): the oracle for the
// simulator. Light leaves on the specular cone theta_r = -theta_i only, so
//   p(theta_r, phi) = delta(theta_r + theta_i) N_p(phi),
//   N_p(phi) = sum over roots h of Phi(p, h) = phi of A(p, h) / |2 dPhi/dh|,
//   Phi(p, h) = 2 p gamma_t - 2 gamma_i + p pi,  sin gamma_i = h,
//   sin gamma_t = h / eta',  eta' = sqrt(eta^2 - sin^2 theta) / cos theta,
//   A(0, h) = f,  A(p, h) = (1 - f)^2 f^(p-1) T^p,
//   f = F(eta, acos(cos theta cos gamma_i)) (exact 3D Fresnel),
//   T = exp(-sigma_a' 2 cos gamma_t)            (Absorption::Chord), or
//   T = exp(-2 sigma_a' (1 + cos 2 gamma_t))    (Absorption::Published,
//                                                Marschner 2003 s4.3),
//   sigma_a' = sigma_a / cos theta_t, sin theta_t = sin theta / eta.
// Bin probabilities never evaluate N_p at a point (it is infinite at the
// caustics): they integrate (1/2) A(p, h) dh over h = sin(gamma_i), split
// wherever Phi(p, .) crosses a phi-bin edge, with Gauss-Legendre on each
// piece, so every quadrature node lies inside one bin and the result is
// exact to rounding through the caustics. Independent of any simulator code.
//
// The path machinery (Bravais index, Phi, the fold, attenuation, node sets
// over h) is analytic/cylinder_paths.h, shared with d'Eon 2011 and
// Marschner 2003.
#include <memory>
#include <vector>

#include "analytic/cylinder_paths.h"
#include "analytic/model.h"

namespace fiberlab::analytic {


// Lobe energies and phi-bin probabilities of the smooth circular fiber at one
// incidence; usable directly by simulator tests.
struct SmoothCylinderPrediction {
  int lobes = 0, n_phi = 0, channels = 0;
  std::vector<double> energy;    // [lobe * C + c] = (1/2) int A dh, p >= L-1 summed
  std::vector<double> phi_bins;  // [(lobe * n_phi + j) * C + c], sums to energy over j
  int max_explicit_p = 0;        // orders traced bin by bin (see below)
  double residual_energy = 0.0;  // max over c of the energy of p > max_explicit_p
};
// The last lobe sums p = L-1 .. P explicitly, P the first order (>= L-1,
// <= max_p) after which the closed-form remaining energy is below
// residual_tol; that remaining energy (exact) is then spread uniformly in
// phi: lobe energies are exact to rounding in any case, and the phi
// distribution's error is bounded by residual_energy.
SmoothCylinderPrediction smooth_cylinder_prediction(double eta, double theta_i,
                                                    const std::vector<double>& sigma_a,
                                                    Absorption absorption, int lobes, int n_phi,
                                                    double residual_tol = 1e-7, int max_p = 100);

// The model's parameters (its table, exact_info() in smooth_cylinder.cpp,
// binds `--set` keys to these fields): a smooth circular fiber has no others.
struct ExactParams {
  double eta = 1.55;
  std::vector<double> sigma_a{0.0, 0.0, 0.0};  // 1/R per channel
  Absorption absorption = Absorption::Published;
  int lobes = 4;  // lobes 0..L-2 separately, lobe L-1 = every p >= L-1
};

// The Model. density() is the delta's weight N_p(phi) per
// unit phi, evaluated from the roots of Phi = phi (infinite at a caustic) and
// valid on theta_r = -theta_i only (0 elsewhere).
class SmoothCylinder : public Model {
 public:
  explicit SmoothCylinder(ExactParams params);
  std::string name() const override { return "exact"; }
  int lobes() const override { return params_.lobes; }
  void density(int lobe, double theta_i, double phi_i, double theta_r, double phi,
               std::vector<double>& out) const override;
  std::vector<double> bin_probabilities(const BinGrid& grid, double theta_i,
                                        double phi_i) const override;

 private:
  ExactParams params_;
};

std::unique_ptr<Model> make_smooth_cylinder(const ExactParams& params);

}  // namespace fiberlab::analytic
