// Reading, checking and writing the YAML configuration (SPEC section 11).
//
// Every problem is reported as a fiberlab::Error with one line:
//   ORIGIN: PATH = VALUE <what is wrong> (<what is allowed>)
// e.g. "configs/x.yaml: fiber.eta = 0.9 is out of range (must be > 1)".
//
// Integers: written as 1000000 or as an exactly integral number such as 1e6
// (accepted); 1.5 is rejected ("is not an integer"). Quoted numbers ("1.5")
// are strings and are rejected where a number is expected.
#include "sim/run/settings.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "common/error.h"
#include "common/physical_limits.h"
#include "common/units.h"
#include "sim/run/yaml_keys.h"

namespace fiberlab::sim {
namespace {

constexpr int kMaxChannels = 64;
constexpr std::size_t kMaxRangeAngles = 100000;  // theta_i {from, to, step}
constexpr std::size_t kMaxBetaEntries = 1024;      // roughness.beta_long/beta_azim lists (8 KiB each)
constexpr double kMaxTallyBytes = 8.0 * 1024 * 1024 * 1024;
constexpr std::uint64_t kIntMax = std::numeric_limits<int>::max();
constexpr std::uint64_t kU64Max = std::numeric_limits<std::uint64_t>::max();
constexpr std::size_t kMaxConfigBytes = std::size_t{16} << 20;  // 16 MiB

const char* const kModels[] = {"smooth", "gaussian", "exit_blur", "beckmann", "ggx"};
const char* const kMaskings[] = {"none", "smith_g1"};
const char* const kHSampling[] = {"stratified", "independent"};
const char* const kPolarizations[] = {"scalar", "stokes"};
const char* const kEstimators[] = {"analog", "expected_value"};
const char* const kThetaBins[] = {"uniform", "equal_area"};

// ---------------------------------------------------------------- text helpers

// Keeps an error message on one line.
std::string one_line(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '\n') out += "\\n";
    else if (c == '\r') out += "\\r";
    else if (c == '\t') out += ' ';
    else out += c;
  }
  return out;
}

std::string join(const std::vector<std::string>& words, const char* sep = ", ") {
  std::string out;
  for (std::size_t i = 0; i < words.size(); ++i) out += (i ? sep : "") + words[i];
  return out;
}

std::string child(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

std::string element(const std::string& path, std::size_t i) {
  return fmt::format("{}[{}]", path, i);
}

bool is_quoted(const YAML::Node& n) { return n.IsScalar() && n.Tag() == "!"; }

// How a value is shown in a message: the scalar as written, or a short flow form.
std::string show(const YAML::Node& n) {
  if (!n.IsDefined() || n.IsNull()) return "null";
  if (is_quoted(n)) return "\"" + n.Scalar() + "\"";
  if (n.IsScalar()) return n.Scalar();
  YAML::Emitter e;
  e << YAML::Flow << n;
  std::string s = e.good() ? e.c_str() : "?";
  if (s.size() > 60) s = s.substr(0, 57) + "...";
  return s;
}

// "is a list" / "is a mapping" / "has no value" for a node that is not a scalar.
std::string kind(const YAML::Node& n) {
  if (n.IsSequence()) return "is a list";
  if (n.IsMap()) return "is a mapping";
  if (n.IsNull()) return "has no value";
  return "is a string";
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] != b[j - 1])});
      diag = up;
    }
  }
  return row[b.size()];
}

// Shortest decimal text that parses back to exactly x.
std::string number_text(double x) { return fmt::format("{}", x); }

// Degrees text d such that deg_to_rad(d) == rad exactly when one exists
// (the shortest such), so that to_yaml -> parse gives the same radians.
std::string degrees_text(double rad) {
  const double deg = rad_to_deg(rad);
  for (int digits = 1; digits <= 17; ++digits) {
    const double d = std::stod(fmt::format("{:.{}g}", deg, digits));
    if (deg_to_rad(d) == rad) return number_text(d);
  }
  double up = deg, down = deg;
  for (int step = 0; step < 64; ++step) {
    up = std::nextafter(up, std::numeric_limits<double>::infinity());
    down = std::nextafter(down, -std::numeric_limits<double>::infinity());
    if (deg_to_rad(up) == rad) return number_text(up);
    if (deg_to_rad(down) == rad) return number_text(down);
  }
  return number_text(deg);
}

std::string list_text(const std::vector<double>& xs, std::string (*text)(double)) {
  std::vector<std::string> parts;
  for (double x : xs) parts.push_back(text(x));
  std::string out = "[";  // (built step by step: GCC 12 -O3 warns on "[" + std::string&&)
  out += join(parts);
  return out += "]";
}

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

// ---------------------------------------------------------------- the reader

// A check on a number and the text that states it ("must be > 1").
struct Rule {
  std::string text;
  std::function<bool(double)> ok;
};

// Reads fields of one config, checking type and range; every error names the
// origin, the dotted path, the value and the allowed range.
class Reader {
 public:
  explicit Reader(std::string origin) : origin_(std::move(origin)) {}

  [[noreturn]] void fail(const std::string& message) const {
    throw Error(one_line(origin_ + ": " + message));
  }

  [[noreturn]] void bad(const std::string& path, const YAML::Node& n, const std::string& problem,
                        const std::string& rule) const {
    fail(fmt::format("{} = {} {} ({})", path, show(n), problem, rule));
  }

  // The one YAML document in `text`; yaml-cpp's syntax errors keep their line/column.
  YAML::Node load(const std::string& text) const {
    std::vector<YAML::Node> docs;
    try {
      docs = YAML::LoadAll(text);
    } catch (const YAML::Exception& e) {
      if (e.mark.is_null()) fail("malformed YAML: " + e.msg);
      fail(fmt::format("malformed YAML at line {}, column {}: {}", e.mark.line + 1,
                       e.mark.column + 1, e.msg));
    }
    if (docs.size() > 1)
      fail(fmt::format("contains {} YAML documents (must be exactly one)", docs.size()));
    if (docs.empty()) return YAML::Node();
    if (const auto key = first_duplicate_key(docs.front()))
      fail(fmt::format("duplicate key {} (each key may appear once)", *key));
    return docs.front();
  }

  // A section (`fiber:` ...): a mapping whose keys are all in `allowed`.
  // An absent or empty section reads as an empty mapping.
  YAML::Node section(const YAML::Node& n, const std::string& path,
                     const std::vector<std::string>& allowed) const {
    if (!n.IsDefined() || n.IsNull()) return YAML::Node(YAML::NodeType::Map);
    const std::string rule = "must be a mapping with keys " + join(allowed);
    if (!n.IsMap()) {
      if (path.empty()) fail(fmt::format("the config {}, expected a mapping ({})", kind(n), rule));
      bad(path, n, n.IsScalar() ? "is not a mapping" : kind(n) + ", expected a mapping", rule);
    }
    check_keys(n, path, allowed);
    return n;
  }

  double number(const YAML::Node& n, const std::string& path, const Rule& rule) const {
    double x = 0.0;
    if (!n.IsScalar()) bad(path, n, kind(n) + ", expected a number", rule.text);
    if (is_quoted(n) || !YAML::convert<double>::decode(n, x))
      bad(path, n, "is not a number", rule.text);
    if (!std::isfinite(x)) bad(path, n, "is not a finite number", rule.text);
    if (!rule.ok(x)) bad(path, n, "is out of range", rule.text);
    return x;
  }

  // An integer in [lo, hi]; "1e6" is accepted when exactly integral, "1.5" is not.
  std::uint64_t integer(const YAML::Node& n, const std::string& path, std::uint64_t lo,
                        std::uint64_t hi) const {
    // Bounds below int's maximum are stated (e.g. --threads' cap); int's own is not.
    const std::string rule = hi < kIntMax ? fmt::format("must be an integer in [{}, {}]", lo, hi)
                                          : fmt::format("must be an integer >= {}", lo);
    if (!n.IsScalar()) bad(path, n, kind(n) + ", expected an integer", rule);
    if (is_quoted(n)) bad(path, n, "is not an integer", rule);
    const std::string& s = n.Scalar();
    std::uint64_t v = 0;
    bool negative = false, too_large = false;
    if (!parse_decimal(s, v, negative, too_large)) {
      double x = 0.0;
      if (!YAML::convert<double>::decode(n, x) || !std::isfinite(x) || x != std::floor(x))
        bad(path, n, "is not an integer", rule);
      negative = x < 0;
      too_large = std::fabs(x) >= 18446744073709551616.0;  // 2^64
      if (!negative && !too_large) v = static_cast<std::uint64_t>(x);
    }
    if (negative && v != 0) bad(path, n, "is out of range", rule);
    if (too_large || v > hi)
      bad(path, n, "is out of range", fmt::format("must be an integer in [{}, {}]", lo, hi));
    if (v < lo) bad(path, n, "is out of range", rule);
    return v;
  }

  int small_integer(const YAML::Node& n, const std::string& path, int lo) const {
    return static_cast<int>(integer(n, path, static_cast<std::uint64_t>(lo), kIntMax));
  }

  // A number, or a list of numbers (each checked, paths path[i]).
  std::vector<double> numbers(const YAML::Node& n, const std::string& path, const Rule& rule,
                              bool list_allowed) const {
    if (!n.IsSequence()) return {number(n, path, rule)};
    if (!list_allowed) bad(path, n, "is a list, expected a number", rule.text);
    if (n.size() == 0) bad(path, n, "is an empty list", rule.text);
    std::vector<double> out;
    for (std::size_t i = 0; i < n.size(); ++i) out.push_back(number(n[i], element(path, i), rule));
    return out;
  }

  // One of a fixed set of words; returns its index in `allowed`.
  template <std::size_t N>
  std::size_t word(const YAML::Node& n, const std::string& path,
                   const char* const (&allowed)[N]) const {
    const std::string rule =
        "must be one of: " + join(std::vector<std::string>(std::begin(allowed), std::end(allowed)));
    if (!n.IsScalar()) bad(path, n, kind(n) + ", expected a word", rule);
    for (std::size_t i = 0; i < N; ++i)
      if (n.Scalar() == allowed[i]) return i;
    bad(path, n, "is not allowed", rule);
  }

  // A file name: a non-empty string on one line.
  std::string file_name(const YAML::Node& n, const std::string& path) const {
    const std::string rule = "must be a non-empty file name without control characters";
    if (!n.IsScalar()) bad(path, n, kind(n) + ", expected a string", rule);
    const std::string& s = n.Scalar();
    if (s.empty()) bad(path, n, "is empty", rule);
    for (unsigned char c : s)
      if (c < 0x20 || c == 0x7f) bad(path, n, "contains a control character", rule);
    return s;
  }

 private:
  // Plain decimal integer text ("123", "+5", "-3"); false for anything else.
  static bool parse_decimal(const std::string& s, std::uint64_t& v, bool& negative,
                            bool& too_large) {
    std::size_t i = (!s.empty() && (s[0] == '+' || s[0] == '-')) ? 1 : 0;
    if (i == s.size() || s.find_first_not_of("0123456789", i) != std::string::npos) return false;
    negative = s[0] == '-';
    const auto r = std::from_chars(s.data() + i, s.data() + s.size(), v);
    too_large = r.ec == std::errc::result_out_of_range;
    return true;
  }

  void check_keys(const YAML::Node& map, const std::string& path,
                  const std::vector<std::string>& allowed) const {
    std::set<std::string> seen;
    for (const auto& kv : map) {
      if (!kv.first.IsScalar())
        fail(fmt::format("{} has a key {} that is not a name (allowed: {})",
                         path.empty() ? "the config" : path, show(kv.first), join(allowed)));
      const std::string key = kv.first.Scalar();
      if (!seen.insert(key).second)
        fail(fmt::format("duplicate key {} (each key may appear once)", child(path, key)));
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
        fail(fmt::format("unknown key {}{} (allowed{}: {})", child(path, key), suggestion(key, allowed),
                         path.empty() ? "" : " in " + path, join(allowed)));
    }
  }

  static std::string suggestion(const std::string& key, const std::vector<std::string>& allowed) {
    for (const auto& a : allowed)
      if (edit_distance(key, a) <= 2) return ", did you mean " + a + "?";
    return "";
  }

  std::string origin_;
};

// ---------------------------------------------------------------- rules

// The bounds and why: common/physical_limits.h.
const Rule kEta{"must be in (1, 1e9]: beyond 1e9 the Fresnel transmittance is lost in rounding",
                [](double x) { return x > 1.0 && x <= kMaxEta; }};
const Rule kEccentricity{"must be in [2.2250738585072014e-308, 1]: a smaller ratio is a subnormal "
                         "double (fewer bits; its inverse overflows below 5.6e-309)",
                         [](double x) { return x >= kMinEccentricity && x <= 1.0; }};
const Rule kTilt{"must be in (-45, 45) degrees", [](double x) { return std::fabs(x) < 45.0; }};
const Rule kNonNegative{"must be a finite number >= 0", [](double x) { return x >= 0.0; }};
const Rule kSigmaA{"must be a finite number >= 0, or a list of 1 to 64 such numbers",
                   [](double x) { return x >= 0.0; }};
const Rule kBeta{"must be in [0, 90] degrees", [](double x) { return x >= 0.0 && x <= 90.0; }};
const Rule kAlpha{"must be in (0, 10]", [](double x) { return x > 0.0 && x <= 10.0; }};
const Rule kThetaI{"must be in (-90, 90) degrees", [](double x) { return std::fabs(x) < 90.0; }};
const Rule kPositive{"must be > 0", [](double x) { return x > 0.0; }};
const Rule kAnyAngle{"must be a finite angle in degrees, a list, or uniform",
                     [](double) { return true; }};

std::vector<double> to_radians(std::vector<double> degrees) {
  for (double& d : degrees) d = deg_to_rad(d);
  return degrees;
}

// ---------------------------------------------------------------- sections

void read_medulla(const Reader& r, const YAML::Node& parent, FiberSettings& f);

void read_fiber(const Reader& r, const YAML::Node& parent, FiberSettings& f) {
  const std::string path = "fiber";
  const YAML::Node n = r.section(parent["fiber"], path,
                                 {"eta", "eccentricity", "scale_tilt", "sigma_a", "melanin", "medulla"});
  if (n["eta"]) f.eta = r.number(n["eta"], "fiber.eta", kEta);
  if (n["eccentricity"])
    f.eccentricity = r.number(n["eccentricity"], "fiber.eccentricity", kEccentricity);
  if (n["scale_tilt"])
    f.scale_tilt = deg_to_rad(r.number(n["scale_tilt"], "fiber.scale_tilt", kTilt));

  if (n["sigma_a"] && n["melanin"])
    r.fail("fiber.sigma_a and fiber.melanin are both given (must give one or the other)");
  if (n["sigma_a"]) {
    const YAML::Node s = n["sigma_a"];
    f.sigma_a = r.numbers(s, "fiber.sigma_a", kSigmaA, true);
    if (f.sigma_a.size() > static_cast<std::size_t>(kMaxChannels))
      r.bad("fiber.sigma_a", s, fmt::format("has {} channels", f.sigma_a.size()),
            fmt::format("must have 1 to {} channels", kMaxChannels));
  }
  if (n["melanin"]) {
    const YAML::Node m = r.section(n["melanin"], "fiber.melanin", {"eumelanin", "pheomelanin"});
    if (m.size() == 0)
      r.bad("fiber.melanin", n["melanin"], "is empty", "must give eumelanin and/or pheomelanin");
    const double ce = m["eumelanin"] ? r.number(m["eumelanin"], "fiber.melanin.eumelanin",
                                                kNonNegative) : 0.0;
    const double cp = m["pheomelanin"] ? r.number(m["pheomelanin"], "fiber.melanin.pheomelanin",
                                                  kNonNegative) : 0.0;
    f.eumelanin = ce;
    f.pheomelanin = cp;
    f.sigma_a = sigma_a_from_melanin(ce, cp);
  }
  read_medulla(r, n, f);
}

const Rule kMedullaRadius{"must be in (0, 1): a fraction of the fiber's semi-axes",
                          [](double x) { return x > 0.0 && x < 1.0; }};
const Rule kAnisotropy{"must be in (-1, 1)", [](double x) { return x > -1.0 && x < 1.0; }};
const Rule kMedullaEta{"must be in [1, 1e9]", [](double x) { return x >= 1.0 && x <= kMaxEta; }};

// fiber.medulla (docs/FUR.md), after the fiber's own keys: its sigma_a has
// the fiber's channels, and its eta defaults to the fiber's.
void read_medulla(const Reader& r, const YAML::Node& parent, FiberSettings& f) {
  const YAML::Node n = parent["medulla"];
  if (!n) return;
  const std::string path = "fiber.medulla";
  const YAML::Node m = r.section(n, path, {"radius", "sigma_s", "sigma_a", "g", "eta"});
  for (const char* key : {"radius", "sigma_s"})
    if (!m[key])
      r.fail(fmt::format("{}.{} is missing (a medulla needs radius in (0, 1) and sigma_s >= 0)",
                         path, key));
  MedullaSettings md;
  md.radius = r.number(m["radius"], path + ".radius", kMedullaRadius);
  md.sigma_s = r.number(m["sigma_s"], path + ".sigma_s", kNonNegative);
  md.sigma_a.assign(f.sigma_a.size(), 0.0);
  if (m["sigma_a"]) {
    const Rule rule{fmt::format("must be a finite number >= 0, or a list of {} such numbers (the "
                                "fiber's channels)", f.sigma_a.size()),
                    kSigmaA.ok};
    md.sigma_a = r.numbers(m["sigma_a"], path + ".sigma_a", rule, true);
    if (md.sigma_a.size() == 1) md.sigma_a.assign(f.sigma_a.size(), md.sigma_a.front());
    if (md.sigma_a.size() != f.sigma_a.size())
      r.bad(path + ".sigma_a", m["sigma_a"], fmt::format("has {} channels", md.sigma_a.size()),
            fmt::format("must have the fiber's {} channels, or be one number", f.sigma_a.size()));
  }
  if (m["g"]) md.g = r.number(m["g"], path + ".g", kAnisotropy);
  md.eta = m["eta"] ? r.number(m["eta"], path + ".eta", kMedullaEta) : f.eta;
  f.medulla = md;
}

// alpha of a microfacet model: a number (isotropic) or [longitudinal, azimuthal].
void read_alpha(const Reader& r, const YAML::Node& n, RoughnessSettings& g) {
  const std::string path = "roughness.alpha";
  const Rule rule{kAlpha.text + "; a number, or a list [longitudinal, azimuthal]", kAlpha.ok};
  const std::vector<double> alpha = r.numbers(n, path, rule, true);
  if (alpha.size() > 2)
    r.bad(path, n, fmt::format("has {} entries", alpha.size()),
          "must be a number or a list of two: [longitudinal, azimuthal], each in (0, 10]");
  g.alpha_long = alpha.front();
  g.alpha_azim = alpha.back();
}

void read_roughness(const Reader& r, const YAML::Node& parent, RoughnessSettings& g) {
  const YAML::Node n = r.section(parent["roughness"], "roughness",
                                 {"model", "beta_long", "beta_azim", "alpha", "masking"});
  if (n["model"]) g.model = static_cast<RoughnessModel>(r.word(n["model"], "roughness.model", kModels));
  const std::string model = to_string(g.model);
  if (g.microfacet()) {
    // Microfacet models take alpha (and masking); the beta keys belong to the others.
    for (const char* key : {"beta_long", "beta_azim"})
      if (n[key])
        r.bad(std::string("roughness.") + key, n[key], "is not allowed for model " + model,
              "models beckmann and ggx take alpha; beta_long and beta_azim belong to smooth, "
              "gaussian and exit_blur");
    if (!n["alpha"])
      r.fail(fmt::format("roughness.alpha is missing (model {} needs alpha in (0, 10]: a number, "
                         "or a list [longitudinal, azimuthal])", model));
    read_alpha(r, n["alpha"], g);
    if (n["masking"])
      g.masking = static_cast<Masking>(r.word(n["masking"], "roughness.masking", kMaskings));
    return;
  }
  if (n["alpha"])
    r.bad("roughness.alpha", n["alpha"], "is not allowed for model " + model,
          "alpha is the roughness of models beckmann and ggx");
  if (n["masking"] &&
      r.word(n["masking"], "roughness.masking", kMaskings) != static_cast<int>(Masking::None))
    r.bad("roughness.masking", n["masking"], "is not allowed for model " + model,
          "masking applies to models beckmann and ggx; the other models lose nothing");
  // One beta for gaussian; a list indexed by p is meaningful only for
  // exit_blur (and accepted, unused, for smooth).
  const bool lists = g.model != RoughnessModel::Gaussian;
  const Rule beta{kBeta.text + (lists ? ", a number or a list indexed by p"
                                      : "; a list is allowed only for model exit_blur"),
                  kBeta.ok};
  if (n["beta_long"])
    g.beta_long = to_radians(r.numbers(n["beta_long"], "roughness.beta_long", beta, lists));
  g.beta_azim = n["beta_azim"]
                    ? to_radians(r.numbers(n["beta_azim"], "roughness.beta_azim", beta, lists))
                    : g.beta_long;
  // Each list is stored in the result as an attribute of /roughness, and an
  // HDF5 1.10 attribute holds at most 64 KiB: refused here, not after the run.
  for (const char* key : {"beta_long", "beta_azim"}) {
    const std::vector<double>& list = std::string(key) == "beta_long" ? g.beta_long : g.beta_azim;
    if (list.size() > kMaxBetaEntries)
      r.bad(std::string("roughness.") + key, n[key], fmt::format("has {} entries", list.size()),
            fmt::format("must have at most {} (one per order p, the last for every larger p)",
                        kMaxBetaEntries));
  }
}

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

// A beta list as YAML: a number when there is one entry.
std::string betas_text(const std::vector<double>& betas) {
  return betas.size() == 1 ? degrees_text(betas.front()) : list_text(betas, degrees_text);
}

// The roughness block's lines after `model:`: alpha and masking for the
// microfacet models, beta_long and beta_azim for the others.
std::string roughness_parameters_text(const RoughnessSettings& g) {
  if (g.microfacet()) {
    const std::string alpha =
        g.alpha_long == g.alpha_azim ? number_text(g.alpha_long)
                                     : list_text({g.alpha_long, g.alpha_azim}, number_text);
    return fmt::format("  alpha: {}\n  masking: {}\n", alpha, to_string(g.masking));
  }
  return fmt::format("  beta_long: {}\n  beta_azim: {}\n", betas_text(g.beta_long),
                     betas_text(g.beta_azim));
}

// The fiber block's medulla line (empty without one).
std::string medulla_text(const std::optional<MedullaSettings>& m) {
  if (!m) return "";
  return fmt::format("  medulla: {{radius: {}, sigma_s: {}, sigma_a: {}, g: {}, eta: {}}}\n",
                     number_text(m->radius), number_text(m->sigma_s),
                     list_text(m->sigma_a, number_text), number_text(m->g), number_text(m->eta));
}

}  // namespace

// ---------------------------------------------------------------- public API

Settings parse_settings_yaml(const std::string& yaml_text, const std::string& origin) {
  const Reader r(origin);
  const YAML::Node doc = r.load(yaml_text);
  // A 0-byte file or one holding only comments is most likely a mistake (a
  // truncated copy, the wrong file): refused rather than run with every default.
  if (!doc.IsDefined() || doc.IsNull())
    r.fail("the config is empty (holds no settings; write at least one key, or {} for every "
           "default)");
  const YAML::Node root =
      r.section(doc, "",
                {"photons", "seed", "output", "fiber", "roughness", "source", "tally",
                 "max_segments", "max_events_per_point", "polarization", "estimator"});
  Settings s;
  s.output = default_output(origin);
  read_top_level(r, root, s);
  read_fiber(r, root, s.fiber);
  read_roughness(r, root, s.roughness);
  // Masking's removed weight is absorbed along the cortex path only
  // (sim/life/exit_scoring.cpp), so the two are not combined.
  if (s.fiber.medulla && s.roughness.masking != Masking::None)
    r.fail("fiber.medulla is not allowed with roughness.masking = smith_g1 (allowed with "
           "masking: none)");
  read_source(r, root, s.source);
  read_tally(r, root, s.tally);
  check_tally_size(r, s);
  check_photon_total(r, s);
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
  const FiberSettings& f = s.fiber;
  const bool melanin = f.eumelanin && f.pheomelanin &&
                       f.sigma_a == sigma_a_from_melanin(*f.eumelanin, *f.pheomelanin);
  const std::string absorption =
      melanin ? fmt::format("melanin: {{eumelanin: {}, pheomelanin: {}}}  # sigma_a = {}",
                            number_text(*f.eumelanin), number_text(*f.pheomelanin),
                            list_text(f.sigma_a, number_text))
              : "sigma_a: " + list_text(f.sigma_a, number_text);
  const std::string phi_i =
      s.source.phi_i_uniform ? "uniform" : list_text(s.source.phi_i, degrees_text);
  return fmt::format(
      "# fiberlab configuration, resolved (angles in degrees)\n"
      "photons: {}\n"
      "seed: {}\n"
      "output: {}\n"
      "fiber:\n"
      "  eta: {}\n"
      "  eccentricity: {}\n"
      "  scale_tilt: {}\n"
      "  {}\n"
      "{}"
      "roughness:\n"
      "  model: {}\n"
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
      "estimator: {}\n",
      s.photons, s.seed, quoted(s.output), number_text(f.eta), number_text(f.eccentricity),
      degrees_text(f.scale_tilt), absorption, medulla_text(f.medulla), to_string(s.roughness.model),
      roughness_parameters_text(s.roughness),
      list_text(s.source.theta_i, degrees_text), phi_i, kHSampling[s.source.h_stratified ? 0 : 1],
      s.tally.n_theta, s.tally.n_phi,
      kThetaBins[s.tally.theta_bins == ThetaBinning::Uniform ? 0 : 1], s.tally.lobes,
      s.max_segments, s.max_events_per_point, to_string(s.polarization),
      to_string(s.estimator));
}

std::vector<double> sigma_a_from_melanin(double eumelanin, double pheomelanin) {
  // d'Eon et al. 2011, section 6.1: absorption per unit radius of each pigment.
  constexpr double eu[3] = {0.419, 0.697, 1.37};
  constexpr double pheo[3] = {0.187, 0.4, 1.05};
  std::vector<double> sigma_a(3);
  for (int c = 0; c < 3; ++c) sigma_a[c] = eumelanin * eu[c] + pheomelanin * pheo[c];
  return sigma_a;
}

std::string to_string(RoughnessModel m) { return kModels[static_cast<int>(m)]; }

std::string to_string(Masking m) { return kMaskings[static_cast<int>(m)]; }

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
