#include "common/config_reader.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <set>

#include <fmt/format.h>

#include "common/error.h"
#include "common/units.h"

namespace fiberlab::config {
namespace {

constexpr std::uint64_t kIntMax = std::numeric_limits<int>::max();

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

std::string suggestion(const std::string& key, const std::vector<std::string>& allowed) {
  for (const auto& a : allowed)
    if (edit_distance(key, a) <= 2) return ", did you mean " + a + "?";
  return "";
}

// Plain decimal integer text ("123", "+5", "-3"); false for anything else.
bool parse_decimal(const std::string& s, std::uint64_t& v, bool& negative, bool& too_large) {
  std::size_t i = (!s.empty() && (s[0] == '+' || s[0] == '-')) ? 1 : 0;
  if (i == s.size() || s.find_first_not_of("0123456789", i) != std::string::npos) return false;
  negative = s[0] == '-';
  const auto r = std::from_chars(s.data() + i, s.data() + s.size(), v);
  too_large = r.ec == std::errc::result_out_of_range;
  return true;
}

}  // namespace

std::string join(const std::vector<std::string>& words, const char* sep) {
  std::string out;
  for (std::size_t i = 0; i < words.size(); ++i) out += (i ? sep : "") + words[i];
  return out;
}

void Reader::fail(const std::string& message) const {
  throw Error(one_line(origin_ + ": " + message));
}

void Reader::bad(const std::string& path, const YAML::Node& n, const std::string& problem,
                 const std::string& rule) const {
  fail(fmt::format("{} = {} {} ({})", path, show(n), problem, rule));
}

YAML::Node Reader::section(const YAML::Node& n, const std::string& path,
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

double Reader::number(const YAML::Node& n, const std::string& path, const Rule& rule) const {
  double x = 0.0;
  if (!n.IsScalar()) bad(path, n, kind(n) + ", expected a number", rule.text);
  if (is_quoted(n) || !YAML::convert<double>::decode(n, x)) bad(path, n, "is not a number", rule.text);
  if (!std::isfinite(x)) bad(path, n, "is not a finite number", rule.text);
  if (!rule.ok(x)) bad(path, n, "is out of range", rule.text);
  return x;
}

std::uint64_t Reader::integer(const YAML::Node& n, const std::string& path, std::uint64_t lo,
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

int Reader::small_integer(const YAML::Node& n, const std::string& path, int lo) const {
  return static_cast<int>(integer(n, path, static_cast<std::uint64_t>(lo), kIntMax));
}

std::vector<double> Reader::numbers(const YAML::Node& n, const std::string& path, const Rule& rule,
                                    bool list_allowed) const {
  if (!n.IsSequence()) return {number(n, path, rule)};
  if (!list_allowed) bad(path, n, "is a list, expected a number", rule.text);
  if (n.size() == 0) bad(path, n, "is an empty list", rule.text);
  std::vector<double> out;
  for (std::size_t i = 0; i < n.size(); ++i) out.push_back(number(n[i], element(path, i), rule));
  return out;
}

std::size_t Reader::word(const YAML::Node& n, const std::string& path,
                         const std::vector<std::string>& allowed) const {
  const std::string rule = "must be one of: " + join(allowed);
  if (!n.IsScalar()) bad(path, n, kind(n) + ", expected a word", rule);
  for (std::size_t i = 0; i < allowed.size(); ++i)
    if (n.Scalar() == allowed[i]) return i;
  bad(path, n, "is not allowed", rule);
}

std::string Reader::file_name(const YAML::Node& n, const std::string& path) const {
  const std::string rule = "must be a non-empty file name without control characters";
  if (!n.IsScalar()) bad(path, n, kind(n) + ", expected a string", rule);
  const std::string& s = n.Scalar();
  if (s.empty()) bad(path, n, "is empty", rule);
  for (unsigned char c : s)
    if (c < 0x20 || c == 0x7f) bad(path, n, "contains a control character", rule);
  return s;
}

void Reader::check_keys(const YAML::Node& map, const std::string& path,
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

std::string number_text(double x) { return fmt::format("{}", x); }

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

std::vector<double> to_radians(std::vector<double> degrees) {
  for (double& d : degrees) d = deg_to_rad(d);
  return degrees;
}

}  // namespace fiberlab::config
