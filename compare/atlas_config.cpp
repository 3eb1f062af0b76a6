#include "compare/atlas_config.h"

#include <fmt/core.h>
#include <fmt/ranges.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>

#include "analytic/model_registry.h"
#include "analytic/physical_defaults.h"
#include "common/config_reader.h"
#include "common/error.h"
#include "common/file_schema.h"
#include "common/fiber.h"
#include "common/units.h"
#include "compare/fit.h"
#include "sim/run/yaml_keys.h"

namespace fiberlab::compare {

namespace {

constexpr std::size_t kMaxConfigBytes = 1 << 20;
constexpr std::size_t kMaxFibers = 10000;

// One-line errors naming the file and the entry.
struct Reader {
  std::string origin;
  [[noreturn]] void fail(const std::string& what) const {
    std::string line = origin + ": " + what;
    for (char& c : line)
      if (c == '\n' || c == '\r') c = ' ';
    throw Error(line);
  }
};

std::string show(const YAML::Node& n) {
  if (!n.IsDefined() || n.IsNull()) return "(nothing)";
  YAML::Emitter e;
  e.SetMapFormat(YAML::Flow);
  e.SetSeqFormat(YAML::Flow);
  e << n;
  return e.c_str();
}

void only_keys(const Reader& r, const YAML::Node& map, const std::string& path,
               const std::set<std::string>& allowed) {
  if (!map.IsMap()) r.fail(fmt::format("{} = {} must be a mapping", path.empty() ? "the config" : path, show(map)));
  std::string list;
  for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
  for (const auto& kv : map) {
    const std::string key = kv.first.Scalar();
    if (!allowed.count(key))
      r.fail(fmt::format("unknown key {}{} (allowed: {})", path.empty() ? "" : path + ".", key, list));
  }
}

double number(const Reader& r, const YAML::Node& n, const std::string& path) {
  double x = 0.0;
  if (!n.IsScalar() || !YAML::convert<double>::decode(n, x) || !std::isfinite(x))
    r.fail(fmt::format("{} = {} must be a finite number", path, show(n)));
  return x;
}

std::uint64_t integer(const Reader& r, const YAML::Node& n, const std::string& path, double lo, double hi) {
  const double x = number(r, n, path);
  if (x != std::floor(x) || x < lo || x > hi)
    r.fail(fmt::format("{} = {} must be an integer in [{:g}, {:g}]", path, show(n), lo, hi));
  return static_cast<std::uint64_t>(x);
}

// A non-empty list (a single value is a list of one).
std::vector<YAML::Node> items(const Reader& r, const YAML::Node& n, const std::string& path) {
  std::vector<YAML::Node> out;
  if (!n.IsDefined() || n.IsNull()) r.fail(fmt::format("{} is missing (a non-empty list)", path));
  if (n.IsSequence()) {
    for (const auto& x : n) out.push_back(x);
  } else {
    out.push_back(n);
  }
  if (out.empty()) r.fail(fmt::format("{} is empty (give at least one entry)", path));
  return out;
}

std::vector<double> numbers(const Reader& r, const YAML::Node& n, const std::string& path) {
  std::vector<double> out;
  const auto list = items(r, n, path);
  for (std::size_t i = 0; i < list.size(); ++i) out.push_back(number(r, list[i], fmt::format("{}[{}]", path, i)));
  return out;
}

// The size of a fiber's roughness for tables and figures: beta_long
// (degrees, as the config wrote it) for gaussian / exit_blur (its first
// entry), alpha (longitudinal) for microfacet models, 0 for smooth.
void roughness_size(const Roughness& roughness, AtlasFiber& f) {
  f.roughness_model = roughness::name(roughness);
  f.roughness = 0.0;
  f.roughness_unit = "";
  const auto degrees = [&](double radians) {
    f.roughness = std::stod(config::degrees_text(radians));
    f.roughness_unit = "deg";
  };
  if (const auto* g = std::get_if<roughness::Gaussian>(&roughness)) degrees(g->beta_long);
  if (const auto* e = std::get_if<roughness::ExitBlur>(&roughness)) degrees(e->beta_long.front());
  if (const auto* m = analytic::microfacet_alpha(roughness)) f.roughness = m->alpha_long;
}

// An absorption entry gives sigma_a or melanin (its values are read and
// checked with the fiber, by the run config's reader).
void check_absorption_entry(const Reader& r, const YAML::Node& entry, const std::string& path) {
  only_keys(r, entry, path, {"sigma_a", "melanin"});
  if (entry["sigma_a"] && entry["melanin"]) r.fail(path + " gives both sigma_a and melanin (give one)");
  if (!entry["sigma_a"] && !entry["melanin"]) r.fail(path + " gives neither sigma_a nor melanin (give one)");
}

// "sigma_a=0.2,0.4" or "melanin 0.8/0.1".
std::string absorption_label(const Fiber& fiber) {
  if (fiber.eumelanin && fiber.pheomelanin)
    return fmt::format("melanin {:g}/{:g}", *fiber.eumelanin, *fiber.pheomelanin);
  std::string s;
  for (double x : fiber.sigma_a) s += (s.empty() ? "" : ",") + fmt::format("{:g}", x);
  return "sigma_a=" + s;
}

// The simulator config of one fiber, parsed by the simulator's own parser.
sim::Settings fiber_settings(const Reader& r, const YAML::Node& top, const YAML::Node& roughness,
                             const YAML::Node& absorption, double tilt, double eccentricity,
                             const YAML::Node& medulla, const YAML::Node& theta_i,
                             const std::string& where) {
  YAML::Node c;
  c["photons"] = top["photons"];
  c["seed"] = top["seed"] ? top["seed"] : YAML::Node(1);
  c["output"] = "atlas_fiber.h5";  // never written: the atlas simulates in process
  YAML::Node fiber;
  fiber["eta"] = top["eta"] ? top["eta"] : YAML::Node(1.55);
  fiber["eccentricity"] = eccentricity;
  fiber["scale_tilt"] = tilt;
  for (const auto& kv : absorption) fiber[kv.first.Scalar()] = kv.second;
  if (!(medulla.IsScalar() && medulla.Scalar() == "none")) fiber["medulla"] = medulla;
  c["fiber"] = fiber;
  c["roughness"] = roughness;
  YAML::Node source;
  source["theta_i"] = theta_i;
  source["phi_i"] = 0.0;
  c["source"] = source;
  if (top["tally"]) c["tally"] = top["tally"];
  YAML::Emitter e;
  e << c;
  try {
    return sim::parse_settings_yaml(e.c_str(), "fiber");
  } catch (const Error& err) {
    r.fail(fmt::format("{}: {}", where, err.what()));
  }
}

// One entry of `models`: a registered model, or a variant (its own name,
// a registered model, fixed parameters).
struct ModelEntry {
  std::string name, model;
  // Null for a registered model's own entry. A pointer: assigning a
  // YAML::Node (as sorting does) rewrites the node it refers to.
  std::shared_ptr<const YAML::Node> parameters;
  std::string path;       // "models[1]", for errors
  std::size_t rank = 0;   // registry index of model
  std::size_t order = 0;  // 0 for a registered model, 1 + config position for a variant
};

bool is_variant_name(const std::string& name) {
  if (name.empty() || name.size() > 64) return false;
  for (char c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-') return false;
  return true;
}

std::size_t registry_index(const std::vector<std::string>& all, const std::string& name) {
  return static_cast<std::size_t>(std::find(all.begin(), all.end(), name) - all.begin());
}

std::string allowed_models(const std::vector<std::string>& all) {
  std::string allowed = "all";
  for (const auto& m : all) allowed += " | " + m;
  return allowed + " | {name: NAME, model: MODEL, parameters: {KEY: VALUE}}";
}

ModelEntry read_variant(const Reader& r, const YAML::Node& n, const std::string& path,
                        const std::vector<std::string>& all, std::size_t i) {
  only_keys(r, n, path, {"name", "model", "parameters"});
  ModelEntry e;
  e.path = path;
  e.order = 1 + i;
  if (!n["name"] || !n["name"].IsScalar() || !is_variant_name(n["name"].Scalar()))
    r.fail(fmt::format("{}.name = {} must be the variant's name (1 to 64 letters, digits, _ or -)", path,
                       show(n["name"])));
  e.name = n["name"].Scalar();
  if (registry_index(all, e.name) < all.size())
    r.fail(fmt::format("{}.name = {} is a registered model's name (give the variant a name of its own)", path, e.name));
  if (!n["model"] || !n["model"].IsScalar() || registry_index(all, n["model"].Scalar()) == all.size()) {
    std::string allowed;
    for (const auto& m : all) allowed += (allowed.empty() ? "" : " | ") + m;
    r.fail(fmt::format("{}.model = {} is not a registered model (allowed: {})", path, show(n["model"]), allowed));
  }
  e.model = n["model"].Scalar();
  e.rank = registry_index(all, e.model);
  if (n["parameters"]) {
    if (!n["parameters"].IsMap())
      r.fail(fmt::format("{}.parameters = {} must be a mapping {{KEY: VALUE}} of {}'s fixed parameters", path,
                         show(n["parameters"]), e.model));
    e.parameters = std::make_shared<const YAML::Node>(n["parameters"]);
  }
  return e;
}

// models: `all` (default) or a list of registered names and variants, in
// the registry's order of their models (a model's variants after it).
std::vector<ModelEntry> read_models(const Reader& r, const YAML::Node& n) {
  const std::vector<std::string> all = analytic::model_names();
  std::vector<ModelEntry> out;
  if (!n || (n.IsScalar() && n.Scalar() == "all")) {
    for (std::size_t j = 0; j < all.size(); ++j) out.push_back({all[j], all[j], {}, "models", j, 0});
    return out;
  }
  std::set<std::string> names;
  const auto list = items(r, n, "models");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string path = fmt::format("models[{}]", i);
    if (list[i].IsMap()) {
      ModelEntry e = read_variant(r, list[i], path, all, i);
      if (!names.insert(e.name).second)
        r.fail(fmt::format("{}.name = {} is already an entry of models (each variant needs its own name)", path, e.name));
      out.push_back(std::move(e));
      continue;
    }
    const std::string name = list[i].IsScalar() ? list[i].Scalar() : show(list[i]);
    const std::size_t j = registry_index(all, name);
    if (j == all.size())
      r.fail(fmt::format("{} = {} is not a registered model (allowed: {})", path, name, allowed_models(all)));
    if (names.insert(name).second) out.push_back({name, name, {}, path, j, 0});
  }
  std::stable_sort(out.begin(), out.end(), [](const ModelEntry& a, const ModelEntry& b) {
    return a.rank != b.rank ? a.rank < b.rank : a.order < b.order;
  });
  return out;
}

// {KEY: VALUE, ...} at `path`: fixed (not free) parameters of `model`'s
// table, each VALUE accepted by the table's own parser (applied to the
// model's defaults here, to each fiber's physical defaults by the atlas).
// Returns "KEY=VALUE" settings.
std::vector<std::string> read_fixed_settings(const Reader& r, const YAML::Node& settings, const std::string& path,
                                             const std::string& model) {
  std::vector<std::string> out;
  const analytic::ParamTable& table = analytic::model_info(model).params;
  std::set<std::string> fixed;
  for (const analytic::ParamSpec& s : table)
    if (!s.free) fixed.insert(s.key);
  if (settings.IsMap())
    for (const auto& setting : settings)
      if (const analytic::ParamSpec* spec = analytic::find_param(table, setting.first.Scalar()); spec && spec->free)
        r.fail(fmt::format("{}.{} is a free parameter: the atlas fits it, starting from the fiber's physical "
                           "value (fixed keys of {}: {})",
                           path, spec->key, model, fmt::join(fixed, ", ")));
  only_keys(r, settings, path, fixed);
  analytic::ModelParameters p = analytic::default_params(model);
  for (const auto& setting : settings) {
    const std::string key = setting.first.Scalar();
    const analytic::ParamSpec* spec = analytic::find_param(table, key);
    // eta, sigma_a, lobes, eccentricity: each fiber's own (the atlas's eta,
    // its absorption and eccentricity sweeps, its tally); a model told
    // otherwise would predict another fiber or another tally shape, and
    // fail only once the fibers are simulated.
    if (spec->from_fiber.rfind("fiber.", 0) == 0 || spec->from_fiber.rfind("tally.", 0) == 0)
      r.fail(fmt::format("{}.{} is each fiber's own ({}): the atlas sets it from its eta, tally and "
                         "sweep, not per model", path, key, spec->from_fiber));
    std::string value;
    if (setting.second.IsScalar()) {
      value = setting.second.Scalar();
    } else if (setting.second.IsSequence()) {  // a per-lobe or per-channel list
      for (const auto& x : setting.second)
        value += (value.empty() ? "" : ",") + (x.IsScalar() ? x.Scalar() : show(x));
    }
    try {
      if (value.empty()) throw Error("empty");
      spec->set(p, value);
    } catch (const Error&) {
      r.fail(fmt::format("{}.{} = {} is not allowed (allowed: {})", path, key, show(setting.second), spec->allowed));
    }
    out.push_back(key + "=" + value);
  }
  return out;
}

// model_parameters: {MODEL: {KEY: VALUE, ...}, ...} for the models of the
// entries; then each variant's: its model's settings with its own on top
// (a key it gives replaces its model's).
std::map<std::string, std::vector<std::string>> read_model_parameters(const Reader& r, const YAML::Node& n,
                                                                      const std::vector<ModelEntry>& entries) {
  std::map<std::string, std::vector<std::string>> out;
  std::set<std::string> chosen;
  for (const ModelEntry& e : entries) chosen.insert(e.model);
  if (n) {
    only_keys(r, n, "model_parameters", chosen);
    for (const auto& kv : n) {
      const std::string model = kv.first.Scalar();
      out[model] = read_fixed_settings(r, kv.second, "model_parameters." + model, model);
    }
  }
  std::map<std::string, std::vector<std::string>> variants;
  for (const ModelEntry& e : entries) {
    if (e.name == e.model) continue;
    std::vector<std::string> settings;
    if (const auto base = out.find(e.model); base != out.end()) settings = base->second;
    if (e.parameters)
      for (const std::string& own : read_fixed_settings(r, *e.parameters, e.path + ".parameters", e.model)) {
        const std::string key = own.substr(0, own.find('=') + 1);
        std::erase_if(settings, [&](const std::string& x) { return x.rfind(key, 0) == 0; });
        settings.push_back(own);
      }
    if (!settings.empty()) variants[e.name] = settings;
  }
  // Settings of a model listed only through its variants are not an entry's.
  for (auto it = out.begin(); it != out.end();)
    it = std::any_of(entries.begin(), entries.end(), [&](const ModelEntry& e) { return e.name == it->first; })
             ? std::next(it)
             : out.erase(it);
  out.merge(variants);
  return out;
}

// fit.model_parameters: {MODEL: {KEY: VALUE, ...}, ...} for the models of the
// entries (model_parameters' rules), given to each entry running MODEL.
std::map<std::string, std::vector<std::string>> read_fit_model_parameters(const Reader& r, const YAML::Node& n,
                                                                          const std::vector<ModelEntry>& entries) {
  std::map<std::string, std::vector<std::string>> out;
  if (!n) return out;
  std::set<std::string> chosen;
  for (const ModelEntry& e : entries) chosen.insert(e.model);
  only_keys(r, n, "fit.model_parameters", chosen);
  for (const auto& kv : n) {
    const std::string model = kv.first.Scalar();
    const std::vector<std::string> settings =
        read_fixed_settings(r, kv.second, "fit.model_parameters." + model, model);
    if (settings.empty()) continue;
    for (const ModelEntry& e : entries)
      if (e.model == model) out[e.name] = settings;
  }
  return out;
}

}  // namespace

AtlasConfig parse_atlas_config(const std::string& yaml_text, const std::string& origin) {
  const Reader r{origin};
  YAML::Node top;
  try {
    top = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    r.fail(fmt::format("malformed YAML at line {}: {}", e.mark.line + 1, e.msg));
  }
  if (!top.IsDefined() || top.IsNull()) r.fail("the config is empty (see configs/atlas_small.yaml)");
  if (const auto key = sim::first_duplicate_key(top))
    r.fail(fmt::format("duplicate key {} (each key may appear once)", *key));
  only_keys(r, top, "", {"photons", "seed", "eta", "tally", "sweep", "models", "model_parameters", "fit"});
  if (!top["photons"]) r.fail("photons is missing (photons per fiber and incident direction, an integer >= 1)");
  integer(r, top["photons"], "photons", 1, 1e12);
  if (!top["sweep"]) r.fail("sweep is missing (roughness, absorption, scale_tilt, eccentricity, theta_i lists)");
  const YAML::Node sweep = top["sweep"];
  only_keys(r, sweep, "sweep", {"roughness", "absorption", "scale_tilt", "eccentricity", "medulla", "theta_i"});

  AtlasConfig c;
  c.path = origin;
  c.yaml = yaml_text;
  const std::vector<ModelEntry> entries = read_models(r, top["models"]);
  for (const ModelEntry& e : entries) {
    c.models.push_back(e.name);
    if (e.name != e.model) c.variant_of[e.name] = e.model;
  }
  c.model_parameters = read_model_parameters(r, top["model_parameters"], entries);
  if (const YAML::Node fit = top["fit"]) {
    only_keys(r, fit, "fit", {"max_iterations", "lobes", "per_lobe", "model_parameters"});
    c.fit_model_parameters = read_fit_model_parameters(r, fit["model_parameters"], entries);
    if (fit["max_iterations"])
      c.max_iterations = static_cast<int>(integer(r, fit["max_iterations"], "fit.max_iterations", 0, 1000));
    if (const YAML::Node per_lobe = fit["per_lobe"]) {
      if (!per_lobe.IsScalar() || (per_lobe.Scalar() != "true" && per_lobe.Scalar() != "false"))
        r.fail(fmt::format("fit.per_lobe = {} must be true or false", show(per_lobe)));
      c.per_lobe = per_lobe.Scalar() == "true";
    }
  }
  const auto roughness = items(r, sweep["roughness"], "sweep.roughness");
  const auto absorption = sweep["absorption"] ? items(r, sweep["absorption"], "sweep.absorption")
                                              : std::vector<YAML::Node>{YAML::Load("{sigma_a: 0.0}")};
  const auto tilts = sweep["scale_tilt"] ? numbers(r, sweep["scale_tilt"], "sweep.scale_tilt") : std::vector<double>{0.0};
  const auto eccs =
      sweep["eccentricity"] ? numbers(r, sweep["eccentricity"], "sweep.eccentricity") : std::vector<double>{1.0};
  // sweep.medulla: `none` or a simulator fiber.medulla block each (docs/FUR.md).
  const auto medullas = sweep["medulla"] ? items(r, sweep["medulla"], "sweep.medulla")
                                         : std::vector<YAML::Node>{YAML::Node("none")};
  for (std::size_t m = 0; m < medullas.size(); ++m)
    if (!medullas[m].IsMap() && !(medullas[m].IsScalar() && medullas[m].Scalar() == "none"))
      r.fail(fmt::format("sweep.medulla[{}] = {} must be none or a medulla block such as "
                         "{{radius: 0.5, sigma_s: 8}}", m, show(medullas[m])));
  const YAML::Node theta_node = sweep["theta_i"];
  const auto theta = numbers(r, theta_node, "sweep.theta_i");
  for (double t : theta) c.theta_i.push_back(deg_to_rad(t));
  for (std::size_t a = 0; a < absorption.size(); ++a)
    check_absorption_entry(r, absorption[a], fmt::format("sweep.absorption[{}]", a));
  for (std::size_t g = 0; g < roughness.size(); ++g)
    if (!roughness[g].IsMap()) r.fail(fmt::format("sweep.roughness[{}] = {} must be a roughness block such as "
                                                  "{{model: gaussian, beta_long: 5}}", g, show(roughness[g])));
  if (roughness.size() * absorption.size() * tilts.size() * eccs.size() * medullas.size() > kMaxFibers)
    r.fail(fmt::format("the sweep has more than {} fibers (shorten its lists)", kMaxFibers));

  for (std::size_t g = 0; g < roughness.size(); ++g)
    for (std::size_t a = 0; a < absorption.size(); ++a)
      for (std::size_t t = 0; t < tilts.size(); ++t)
        for (std::size_t e = 0; e < eccs.size(); ++e)
        for (std::size_t m = 0; m < medullas.size(); ++m) {
          AtlasFiber f;
          const std::string where =
              fmt::format("sweep.roughness[{}] x absorption[{}] x scale_tilt[{}] x eccentricity[{}]", g, a, t, e) +
              (sweep["medulla"] ? fmt::format(" x medulla[{}]", m) : "");
          f.settings = fiber_settings(r, top, roughness[g], absorption[a], tilts[t], eccs[e], medullas[m],
                                      theta_node, where);
          f.medulla_index = static_cast<int>(m);
          f.roughness_index = static_cast<int>(g);
          f.absorption_index = static_cast<int>(a);
          f.tilt_index = static_cast<int>(t);
          f.eccentricity_index = static_cast<int>(e);
          roughness_size(f.settings.fiber.roughness, f);
          f.absorption_label = absorption_label(f.settings.fiber);
          const std::string size = f.roughness_model == "smooth" ? ""
                                   : f.roughness_unit == "deg" ? fmt::format(" {:g} deg", f.roughness)
                                                               : fmt::format(" alpha {:g}", f.roughness);
          f.label = fmt::format("{}{}, {}, tilt {:g}, e {:g}", f.roughness_model, size, f.absorption_label,
                                tilts[t], eccs[e]);
          if (const auto& md = f.settings.fiber.medulla)
            f.label += fmt::format(", medulla k {:g} sigma_s {:g}", md->radius, md->sigma_s);
          c.fibers.push_back(std::move(f));
        }
  // fit.lobes: names on the atlas's lobe axis (`scattered` too when a fiber has a medulla).
  if (top["fit"] && top["fit"]["lobes"]) {
    const YAML::Node lobes = top["fit"]["lobes"];
    std::vector<std::string> names;
    for (const YAML::Node& n : items(r, lobes, "fit.lobes")) {
      if (!n.IsScalar()) r.fail(fmt::format("fit.lobes: {} must be a lobe name such as TT", show(n)));
      names.push_back(n.Scalar());
    }
    try {
      c.fit_lobes = parse_fit_lobes(names, atlas_lobe_names(c.fibers), "fit.lobes");
    } catch (const Error& e) {
      r.fail(e.what());
    }
  }
  return c;
}

AtlasConfig load_atlas_config(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw Error(path + ": cannot read atlas config: it is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot read atlas config: no such readable file");
  std::string text(kMaxConfigBytes + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (in.bad()) throw Error(path + ": cannot read atlas config: read error");
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (text.size() > kMaxConfigBytes) throw Error(path + ": atlas config is larger than 1 MiB");
  return parse_atlas_config(text, path);
}

std::vector<std::string> fiber_lobe_names(const AtlasFiber& fiber) {
  const sim::Settings& s = fiber.settings;
  return lobe_names(s.tally_lobes(), s.fiber.medulla.has_value());
}

std::vector<std::string> atlas_lobe_names(const std::vector<AtlasFiber>& fibers) {
  std::vector<std::string> longest;
  for (const AtlasFiber& f : fibers) {
    std::vector<std::string> names = fiber_lobe_names(f);
    if (names.size() > longest.size()) longest = std::move(names);
  }
  return longest;
}

const std::string& registered_model(const AtlasConfig& config, const std::string& entry) {
  const auto it = config.variant_of.find(entry);
  return it == config.variant_of.end() ? entry : it->second;
}

void override_photons(AtlasConfig& config, const std::string& flag_text) {
  const std::uint64_t n = sim::parse_integer_flag("--photons", flag_text, 1, 1000000000000ULL);
  for (AtlasFiber& f : config.fibers) f.settings.photons = n;
}

}  // namespace fiberlab::compare
