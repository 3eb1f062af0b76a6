#include "common/roughness/roughness.h"

#include <algorithm>

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

constexpr const Roughness* kVariant = nullptr;

}  // namespace

Roughness read(const config::Reader& r, const YAML::Node& config) {
  const YAML::Node n = r.section(config["roughness"], "roughness", keys_of(kVariant));
  const std::vector<std::string> names = names_of(kVariant);
  const std::size_t model =
      n["model"] ? r.word(n["model"], "roughness.model", names)
                 : static_cast<std::size_t>(Roughness(Gaussian{}).index());
  return read_model(kVariant, model, r, n);
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
