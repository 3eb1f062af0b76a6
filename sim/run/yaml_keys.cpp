#include "sim/run/yaml_keys.h"

#include <fmt/core.h>
#include <yaml-cpp/yaml.h>

#include <set>

namespace fiberlab::sim {

namespace {

// Depth-first, keys in document order; `path` is the node's own path.
std::optional<std::string> walk(const YAML::Node& node, const std::string& path, int depth) {
  // YAML aliases can nest deeply; a config is shallow (the readers refuse
  // anything deeper than their sections anyway).
  if (depth > 64) return std::nullopt;
  if (node.IsMap()) {
    std::set<std::string> seen;
    for (const auto& kv : node) {
      const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "?";
      const std::string here = path.empty() ? key : path + "." + key;
      if (kv.first.IsScalar() && !seen.insert(key).second) return here;
      if (auto inner = walk(kv.second, here, depth + 1)) return inner;
    }
  } else if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i)
      if (auto inner = walk(node[i], fmt::format("{}[{}]", path, i), depth + 1)) return inner;
  }
  return std::nullopt;
}

}  // namespace

std::optional<std::string> first_duplicate_key(const YAML::Node& node) { return walk(node, "", 0); }

}  // namespace fiberlab::sim
