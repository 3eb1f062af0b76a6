#include "common/roughness/roughness.h"

#include <algorithm>
#include <type_traits>

#include <fmt/format.h>

namespace fiberlab::roughness {
namespace {

template <class... Models>
std::vector<std::string> names_of(const std::variant<Models...>*) {
  return {Models::kName...};
}

// "model" and then every model's keys, in the variant's order, each once.
template <class... Models>
std::vector<std::string> keys_of(const std::variant<Models...>*) {
  std::vector<std::string> keys{"model"};
  for (const std::vector<std::string>* k : {&Models::keys()...})
    for (const std::string& key : *k)
      if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.push_back(key);
  return keys;
}

// The model of index i, read from section n.
template <class... Models>
Roughness read_model(const std::variant<Models...>*, std::size_t i, const config::Reader& r,
                     const YAML::Node& n) {
  using Reader = Roughness (*)(const config::Reader&, const YAML::Node&);
  const Reader readers[] = {[](const config::Reader& rr, const YAML::Node& nn) -> Roughness {
    return Models::read(rr, nn);
  }...};
  return readers[i](r, n);
}

// After the model's own read (which names the other models' keys it meets
// in its own words): any key the model does not take is refused, so a key of
// another model is never dropped. `masking: none` means no masking for
// every model (microfacet.h).
void refuse_other_keys(const config::Reader& r, const YAML::Node& n, const Roughness& g) {
  const std::vector<std::string>& own = std::visit([](const auto& m) -> const std::vector<std::string>& {
    return std::decay_t<decltype(m)>::keys();
  }, g);
  for (const auto& kv : n) {
    const std::string key = kv.first.Scalar();
    if (key == "model" || std::find(own.begin(), own.end(), key) != own.end()) continue;
    if (key == "masking" && kv.second.IsScalar() && kv.second.Scalar() == "none") continue;
    r.bad("roughness." + key, kv.second, "is not allowed for model " + name(g),
          fmt::format("model {} takes {}", name(g), own.empty() ? "no other key" : config::join(own)));
  }
}

constexpr const Roughness* kVariant = nullptr;

}  // namespace

Roughness read(const config::Reader& r, const YAML::Node& config) {
  const YAML::Node n = r.section(config["roughness"], "roughness", keys_of(kVariant));
  const std::vector<std::string> names = names_of(kVariant);
  const std::size_t model =
      n["model"] ? r.word(n["model"], "roughness.model", names)
                 : static_cast<std::size_t>(Roughness(Gaussian{}).index());
  const Roughness g = read_model(kVariant, model, r, n);
  refuse_other_keys(r, n, g);
  return g;
}

std::string name(const Roughness& g) {
  return std::visit([](const auto& m) -> std::string { return m.kName; }, g);
}

std::string yaml(const Roughness& g) {
  return fmt::format("roughness:\n  model: {}\n{}", name(g), std::visit([](const auto& m) { return m.yaml(); }, g));
}

std::vector<Attribute> attributes(const Roughness& g) {
  return std::visit([](const auto& m) { return m.attributes(); }, g);
}

std::string describe(const Roughness& g) {
  return name(g) + ", " + std::visit([](const auto& m) { return m.describe(); }, g);
}

std::string text(const Roughness& g) {
  return std::visit([](const auto& m) { return m.text(); }, g);
}

Masking masking(const Roughness& g) {
  return std::visit(
      [](const auto& m) {
        if constexpr (requires { m.masking; }) return m.masking;
        else return Masking::None;
      },
      g);
}

}  // namespace fiberlab::roughness
