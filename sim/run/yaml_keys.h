#pragma once
// Duplicate keys in a YAML document. yaml-cpp keeps both entries of a
// repeated key and `node[key]` returns the first, so a config that says
// `eta: 1.55` and later `eta: 1.6` would silently run with one of them.
// Every config reader (run configs, atlas configs) refuses them with this
// one walk.
#include <optional>
#include <string>

namespace YAML {
class Node;
}

namespace fiberlab::sim {

// The dotted path of the first key that appears twice in one mapping, at any
// depth ("fiber.eta", "sweep.roughness[1].model"), or nullopt.
std::optional<std::string> first_duplicate_key(const YAML::Node& node);

}  // namespace fiberlab::sim
