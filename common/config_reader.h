#pragma once
// Reading and writing config fields (SPEC section 11), shared by every part
// of the configuration that reads YAML: the run config (sim/run/settings.cpp)
// and the fiber description with its roughness (common/fiber.h).
//
// Every problem is reported as a fiberlab::Error with one line:
//   ORIGIN: PATH = VALUE <what is wrong> (<what is allowed>)
// e.g. "configs/x.yaml: fiber.eta = 0.9 is out of range (must be > 1)".
//
// Integers: written as 1000000 or as an exactly integral number such as 1e6
// (accepted); 1.5 is rejected ("is not an integer"). Quoted numbers ("1.5")
// are strings and are rejected where a number is expected.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace fiberlab::config {

// A check on a number and the text that states it ("must be > 1").
struct Rule {
  std::string text;
  std::function<bool(double)> ok;
};

std::string join(const std::vector<std::string>& words, const char* sep = ", ");

// Reads fields of one config, checking type and range; every error names the
// origin, the dotted path, the value and the allowed range.
class Reader {
 public:
  explicit Reader(std::string origin) : origin_(std::move(origin)) {}

  [[noreturn]] void fail(const std::string& message) const;
  [[noreturn]] void bad(const std::string& path, const YAML::Node& n, const std::string& problem,
                        const std::string& rule) const;

  // A section (`fiber:` ...): a mapping whose keys are all in `allowed`.
  // An absent or empty section reads as an empty mapping.
  YAML::Node section(const YAML::Node& n, const std::string& path,
                     const std::vector<std::string>& allowed) const;

  double number(const YAML::Node& n, const std::string& path, const Rule& rule) const;

  // An integer in [lo, hi]; "1e6" is accepted when exactly integral, "1.5" is not.
  std::uint64_t integer(const YAML::Node& n, const std::string& path, std::uint64_t lo,
                        std::uint64_t hi) const;
  int small_integer(const YAML::Node& n, const std::string& path, int lo) const;

  // A number, or a list of numbers (each checked, paths path[i]).
  std::vector<double> numbers(const YAML::Node& n, const std::string& path, const Rule& rule,
                              bool list_allowed) const;

  // One of a fixed set of words; returns its index in `allowed`.
  template <std::size_t N>
  std::size_t word(const YAML::Node& n, const std::string& path,
                   const char* const (&allowed)[N]) const {
    return word(n, path, std::vector<std::string>(std::begin(allowed), std::end(allowed)));
  }
  std::size_t word(const YAML::Node& n, const std::string& path,
                   const std::vector<std::string>& allowed) const;

  // A file name: a non-empty string on one line.
  std::string file_name(const YAML::Node& n, const std::string& path) const;

 private:
  void check_keys(const YAML::Node& map, const std::string& path,
                  const std::vector<std::string>& allowed) const;

  std::string origin_;
};

// Shortest decimal text that parses back to exactly x.
std::string number_text(double x);
// Degrees text d such that deg_to_rad(d) == rad exactly when one exists
// (the shortest such), so that writing and reading back give the same radians.
std::string degrees_text(double rad);
// "[a, b, c]", each entry by `text`.
std::string list_text(const std::vector<double>& xs, std::string (*text)(double));
std::vector<double> to_radians(std::vector<double> degrees);

}  // namespace fiberlab::config
