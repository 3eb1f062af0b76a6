// Reading, checking and writing the YAML configuration (SPEC section 11);
// the field readers and the error format: common/config_reader.h.
#include "sim/run/settings.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "common/error.h"
#include "common/units.h"
#include "sim/run/yaml_keys.h"

namespace fiberlab::sim {
namespace {

constexpr std::size_t kMaxRangeAngles = 100000;  // theta_i {from, to, step}
constexpr double kMaxTallyBytes = 8.0 * 1024 * 1024 * 1024;
constexpr std::uint64_t kU64Max = std::numeric_limits<std::uint64_t>::max();
constexpr std::size_t kMaxConfigBytes = std::size_t{16} << 20;  // 16 MiB

const char* const kHSampling[] = {"stratified", "independent"};
const char* const kPolarizations[] = {"scalar", "stokes"};
const char* const kEstimators[] = {"analog", "expected_value"};
const char* const kThetaBins[] = {"uniform", "equal_area"};

using config::degrees_text;
using config::list_text;
using config::number_text;
using config::Reader;
using config::Rule;
using config::to_radians;

// A string in YAML double quotes (\" \\ and control characters escaped).
std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    if (c == '"' || c == '\\') out += {'\\', static_cast<char>(c)};
    else if (c < 0x20 || c == 0x7f) out += fmt::format("\\x{:02x}", c);
    else out += static_cast<char>(c);
  }
  return out + "\"";
}

// The one YAML document in `text`; yaml-cpp's syntax errors keep their line/column.
YAML::Node load_document(const Reader& r, const std::string& text) {
  std::vector<YAML::Node> docs;
  try {
    docs = YAML::LoadAll(text);
  } catch (const YAML::Exception& e) {
    if (e.mark.is_null()) r.fail("malformed YAML: " + e.msg);
    r.fail(fmt::format("malformed YAML at line {}, column {}: {}", e.mark.line + 1,
                       e.mark.column + 1, e.msg));
  }
  if (docs.size() > 1)
    r.fail(fmt::format("contains {} YAML documents (must be exactly one)", docs.size()));
  if (docs.empty()) return YAML::Node();
  if (const auto key = first_duplicate_key(docs.front()))
    r.fail(fmt::format("duplicate key {} (each key may appear once)", *key));
  return docs.front();
}

// ---------------------------------------------------------------- rules

const Rule kThetaI{"must be in (-90, 90) degrees", [](double x) { return std::fabs(x) < 90.0; }};
const Rule kPositive{"must be > 0", [](double x) { return x > 0.0; }};
const Rule kAnyAngle{"must be a finite angle in degrees, a list, or uniform",
                     [](double) { return true; }};

// ---------------------------------------------------------------- sections

// theta_i: {from, to, step} in degrees, `to` included within 1e-9 of a step.
std::vector<double> read_theta_range(const Reader& r, const YAML::Node& n) {
  const std::string path = "source.theta_i";
  const YAML::Node m = r.section(n, path, {"from", "to", "step"});
  for (const char* key : {"from", "to", "step"})
    if (!m[key])
      r.fail(fmt::format("{}.{} is missing (a range needs from, to and step)", path, key));
  const double from = r.number(m["from"], path + ".from", kThetaI);
  const double to = r.number(m["to"], path + ".to", kThetaI);
  const double step = r.number(m["step"], path + ".step", kPositive);
  if (to < from) r.bad(path + ".to", m["to"], "is out of range", fmt::format("must be >= from = {}", from));
  const double count = std::floor((to - from) / step + 1e-9) + 1.0;
  if (count > static_cast<double>(kMaxRangeAngles))
    r.bad(path, n, fmt::format("gives {} angles", static_cast<std::uint64_t>(count)),
          fmt::format("must give at most {}", kMaxRangeAngles));
  // from + i*step, rounded to 12 significant digits so that 0.1-steps give
  // 0.3 rather than 0.30000000000000004, and never beyond `to`.
  std::vector<double> degrees;
  for (std::size_t i = 0; i < static_cast<std::size_t>(count); ++i) {
    const double x = from + static_cast<double>(i) * step;
    degrees.push_back(std::min(std::stod(fmt::format("{:.12g}", x)), to));
  }
  return degrees;
}

void read_source(const Reader& r, const YAML::Node& parent, SourceSettings& s) {
  const YAML::Node n = r.section(parent["source"], "source", {"theta_i", "phi_i", "h_sampling"});
  if (const YAML::Node t = n["theta_i"]) {
    const Rule rule{kThetaI.text + "; a number, a list, or {from, to, step}", kThetaI.ok};
    s.theta_i = to_radians(t.IsMap() ? read_theta_range(r, t)
                                     : r.numbers(t, "source.theta_i", rule, true));
  }
  if (const YAML::Node p = n["phi_i"]) {
    s.phi_i_uniform = p.IsScalar() && p.Scalar() == "uniform";
    if (!s.phi_i_uniform) s.phi_i = to_radians(r.numbers(p, "source.phi_i", kAnyAngle, true));
  }
  if (n["h_sampling"]) s.h_stratified = r.word(n["h_sampling"], "source.h_sampling", kHSampling) == 0;
}

void read_tally(const Reader& r, const YAML::Node& parent, TallySettings& t) {
  const YAML::Node n =
      r.section(parent["tally"], "tally", {"n_theta", "n_phi", "theta_bins", "lobes"});
  if (n["n_theta"]) t.n_theta = r.small_integer(n["n_theta"], "tally.n_theta", 1);
  if (n["n_phi"]) t.n_phi = r.small_integer(n["n_phi"], "tally.n_phi", 1);
  if (n["theta_bins"])
    t.theta_bins = r.word(n["theta_bins"], "tally.theta_bins", kThetaBins) == 0
                       ? ThetaBinning::Uniform
                       : ThetaBinning::EqualArea;
  if (n["lobes"]) t.lobes = r.small_integer(n["lobes"], "tally.lobes", 1);
}

// exit_normals: an integer in [1, kMaxExitNormals], or a list of them by lobe p.
std::vector<int> read_exit_normals(const Reader& r, const YAML::Node& n) {
  const auto one = [&](const YAML::Node& x, const std::string& path) {
    return static_cast<int>(r.integer(x, path, 1, kMaxExitNormals));
  };
  if (!n.IsSequence()) return {one(n, "exit_normals")};
  if (n.size() == 0 || n.size() > kMaxExitNormalsEntries)
    r.bad("exit_normals", n, fmt::format("has {} entries", n.size()),
          fmt::format("an integer in [1, {}], or a list of at most {} of them by lobe p", kMaxExitNormals,
                      kMaxExitNormalsEntries));
  std::vector<int> k;
  for (std::size_t i = 0; i < n.size(); ++i) k.push_back(one(n[i], fmt::format("exit_normals[{}]", i)));
  return k;
}

void read_top_level(const Reader& r, const YAML::Node& n, Settings& s) {
  if (n["photons"]) s.photons = r.integer(n["photons"], "photons", 1, kU64Max);
  if (n["seed"]) s.seed = r.integer(n["seed"], "seed", 0, kU64Max);
  if (n["output"]) s.output = r.file_name(n["output"], "output");
  if (n["max_segments"]) s.max_segments = r.small_integer(n["max_segments"], "max_segments", 1);
  if (n["max_events_per_point"])
    s.max_events_per_point = r.small_integer(n["max_events_per_point"], "max_events_per_point", 1);
  if (n["polarization"])
    s.polarization = static_cast<Polarization>(r.word(n["polarization"], "polarization", kPolarizations));
  if (n["estimator"])
    s.estimator = static_cast<Estimator>(r.word(n["estimator"], "estimator", kEstimators));
  if (n["exit_normals"]) s.exit_normals = read_exit_normals(r, n["exit_normals"]);
}

// Whether the fiber's roughness model draws a random normal at each event
// (what exit_normals spreads a scored exit over).
bool draws_random_normals(const Roughness& r) {
  if (const auto* g = std::get_if<roughness::Gaussian>(&r)) return g->beta_long != 0.0 || g->beta_azim != 0.0;
  return std::holds_alternative<roughness::Beckmann>(r) || std::holds_alternative<roughness::Ggx>(r);
}

// exit_normals > 1 spreads an exit scored by expected value over normals of
// the event's roughness, with the scalar leaving probability F.
void check_exit_normals(const Reader& r, const Settings& s) {
  if (std::all_of(s.exit_normals.begin(), s.exit_normals.end(), [](int k) { return k == 1; })) return;
  const std::string value = list_text(std::vector<double>(s.exit_normals.begin(), s.exit_normals.end()), number_text);
  if (s.estimator != Estimator::ExpectedValue)
    r.fail(fmt::format("exit_normals = {} needs estimator: expected_value (it spreads the exits that estimator "
                       "scores; with estimator: {} every entry must be 1)", value, to_string(s.estimator)));
  if (s.polarization != Polarization::Scalar)
    r.fail(fmt::format("exit_normals = {} needs polarization: scalar (with stokes every entry must be 1)", value));
  if (!draws_random_normals(s.fiber.roughness))
    r.fail(fmt::format("exit_normals = {} needs a roughness whose normals are random (gaussian with beta > 0, "
                       "beckmann or ggx; with roughness.model {} every entry must be 1)",
                       value, roughness::name(s.fiber.roughness)));
}

// The tally holds S1 and S2 doubles for every incidence, lobe, bin and channel.
void check_tally_size(const Reader& r, const Settings& s) {
  const double incidences = static_cast<double>(s.source.theta_i.size()) *
                            (s.source.phi_i_uniform ? 1.0 : static_cast<double>(s.source.phi_i.size()));
  const double bytes = incidences * s.tally_lobes() * static_cast<double>(s.tally.n_theta) *
                       s.tally.n_phi * static_cast<double>(s.fiber.sigma_a.size()) * 2.0 * 8.0;
  if (bytes > kMaxTallyBytes)
    r.fail(fmt::format(
        "tally.n_theta = {} x tally.n_phi = {} is too large: the tally would need {:.1f} GiB for "
        "{} incident configuration(s) x {} lobes x {} channel(s) (must be at most 8 GiB; lower "
        "tally.n_theta/n_phi, tally.lobes, the channels or the incident angles)",
        s.tally.n_theta, s.tally.n_phi, bytes / (1024.0 * 1024 * 1024),
        static_cast<std::uint64_t>(incidences), s.tally_lobes(),
        s.fiber.sigma_a.size()));
}

// photons x incident configurations is counted in uint64 (progress, totals).
void check_photon_total(const Reader& r, const Settings& s) {
  const std::uint64_t k = s.incidences().size();
  if (k > 0 && s.photons > kU64Max / k)
    r.fail(fmt::format("photons = {} x {} incident configurations exceeds 2^64 - 1 photons in "
                       "total (lower photons or the incident angles)", s.photons, k));
}

std::string default_output(const std::string& origin) {
  const std::string stem = std::filesystem::path(origin).stem().string();
  return stem.empty() ? "out.h5" : stem + ".h5";
}

}  // namespace

// ---------------------------------------------------------------- public API

Settings parse_settings_yaml(const std::string& yaml_text, const std::string& origin) {
  const Reader r(origin);
  const YAML::Node doc = load_document(r, yaml_text);
  // A 0-byte file or one holding only comments is most likely a mistake (a
  // truncated copy, the wrong file): refused rather than run with every default.
  if (!doc.IsDefined() || doc.IsNull())
    r.fail("the config is empty (holds no settings; write at least one key, or {} for every "
           "default)");
  const YAML::Node root =
      r.section(doc, "",
                {"photons", "seed", "output", "fiber", "roughness", "source", "tally",
                 "max_segments", "max_events_per_point", "polarization", "estimator", "exit_normals"});
  Settings s;
  s.output = default_output(origin);
  read_top_level(r, root, s);
  s.fiber = read_fiber(r, root);
  read_source(r, root, s.source);
  read_tally(r, root, s.tally);
  check_tally_size(r, s);
  check_photon_total(r, s);
  check_exit_normals(r, s);
  return s;
}

Settings parse_stored_settings_yaml(const std::string& yaml_text, const std::string& origin) {
  Settings s = parse_settings_yaml(yaml_text, origin);
  const YAML::Node doc = YAML::Load(yaml_text);
  if (doc.IsMap() && !doc["estimator"]) s.estimator = Estimator::Analog;
  return s;
}

Settings load_settings(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw Error(path + ": cannot read config file: it is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot read config file: " + std::strerror(errno));
  // Read at most kMaxConfigBytes + 1: a stream that never ends (/dev/zero, a
  // FIFO) is refused instead of filling memory.
  // (Read in pieces: a buffer of the whole bound, zeroed, cost 16 MiB of page
  // faults per run.)
  std::string text;
  char piece[65536];
  while (text.size() <= kMaxConfigBytes && in) {
    in.read(piece, sizeof piece);
    text.append(piece, static_cast<std::size_t>(in.gcount()));
  }
  if (in.bad()) throw Error(path + ": cannot read config file: read error");
  if (text.size() > kMaxConfigBytes)
    throw Error(fmt::format("{}: config file is larger than {} MiB (a config is a few hundred "
                            "bytes; is this the right file?)", path, kMaxConfigBytes >> 20));
  return parse_settings_yaml(text, path);
}

std::uint64_t parse_integer_flag(const std::string& flag, const std::string& text,
                                 std::uint64_t lo, std::uint64_t hi) {
  const Reader r("command line");
  return r.integer(YAML::Node(text), flag, lo, hi);
}

std::string to_yaml(const Settings& s) {
  const std::string phi_i =
      s.source.phi_i_uniform ? "uniform" : list_text(s.source.phi_i, degrees_text);
  return fmt::format(
      "# fiberlab configuration, resolved (angles in degrees)\n"
      "photons: {}\n"
      "seed: {}\n"
      "output: {}\n"
      "{}"
      "source:\n"
      "  theta_i: {}\n"
      "  phi_i: {}\n"
      "  h_sampling: {}\n"
      "tally:\n"
      "  n_theta: {}\n"
      "  n_phi: {}\n"
      "  theta_bins: {}\n"
      "  lobes: {}\n"
      "max_segments: {}\n"
      "max_events_per_point: {}\n"
      "polarization: {}\n"
      "estimator: {}\n"
      "exit_normals: {}\n",
      s.photons, s.seed, quoted(s.output), fiber_yaml(s.fiber),
      list_text(s.source.theta_i, degrees_text), phi_i, kHSampling[s.source.h_stratified ? 0 : 1],
      s.tally.n_theta, s.tally.n_phi,
      kThetaBins[s.tally.theta_bins == ThetaBinning::Uniform ? 0 : 1], s.tally.lobes,
      s.max_segments, s.max_events_per_point, to_string(s.polarization),
      to_string(s.estimator),
      list_text(std::vector<double>(s.exit_normals.begin(), s.exit_normals.end()), number_text));
}

std::string to_string(Polarization p) { return kPolarizations[static_cast<int>(p)]; }

std::string to_string(Estimator e) { return kEstimators[static_cast<int>(e)]; }

std::vector<Settings::Incidence> Settings::incidences() const {
  std::vector<Incidence> out;
  for (double theta : source.theta_i) {
    if (source.phi_i_uniform) {
      out.push_back({theta, std::numeric_limits<double>::quiet_NaN()});
      continue;
    }
    for (double phi : source.phi_i) out.push_back({theta, phi});
  }
  return out;
}

}  // namespace fiberlab::sim
