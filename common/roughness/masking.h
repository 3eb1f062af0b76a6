#pragma once
// `roughness.masking` of the microfacet models: `smith_g1` multiplies the
// photon's weight by Smith's G1 of each scattered direction and kills paths
// that leave on the wrong side of the mean surface (Huang et al. 2022's
// ground truth); the removed weight is the ledger's `lost`.
#include <string>

namespace fiberlab {

enum class Masking { None, SmithG1 };

inline const char* const kMaskingNames[] = {"none", "smith_g1"};

inline std::string to_string(Masking m) { return kMaskingNames[static_cast<int>(m)]; }

}  // namespace fiberlab
