#pragma once
// ModelParams from the command line (`--set KEY=VALUE`, angles in degrees)
// and back out as a list of attributes for result files (angles in radians).
#include <string>
#include <vector>

#include "analytic/model.h"

namespace fiberlab::analytic {

// Keys (lists are comma separated, indexed by lobe p, the last entry for
// every larger p):
//   eta              > 1
//   sigma_a          list, >= 0, 1/R per channel
//   beta_long        list, degrees, >= 0
//   beta_azim        list, degrees, >= 0
//   alpha            list, degrees (shift of theta_r per p)
//   absorption       published | chord
//   longitudinal     theta_h | two_theta_h          (marschner2003)
//   roots            cubic | exact                   (marschner2003)
//   eccentricity     (0, 1]
//   k_g              >= 0                            (marschner2003)
//   w_c              degrees, >= 0                   (marschner2003)
//   delta_eta        >= 0, unitless                  (marschner2003)
//   delta_h_m        >= 0, unitless (in h, Marschner's Delta h_M = 0.5)
//   lobes            integer >= 1
//   quadrature_order integer >= 1                    (deon2011)
//   r_fresnel        half_angle | per_h              (deon2011)
//   max_order        integer >= 1, default 40        (deon2011: last explicit p)
//   n_theta_d        exit | specular                 (deon2011: theta_d of N_p)
// Throws fiberlab::Error, one line naming the key and the allowed values.
void apply_setting(ModelParams& params, const std::string& key_value);
void apply_settings(ModelParams& params, const std::vector<std::string>& key_values);

// Every parameter by its --set name, as a string or as numbers (radians).
struct ParamAttribute {
  std::string name;
  bool is_text = false;
  std::string text;
  std::vector<double> numbers;
};
std::vector<ParamAttribute> to_attributes(const ModelParams& params);

}  // namespace fiberlab::analytic
