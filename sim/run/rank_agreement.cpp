#include "sim/run/rank_agreement.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace fiberlab::sim {

namespace {

// FNV-1a, 64 bits: a digest per line (a differing line is found by comparing
// digests, so only rank 0's digests travel, not its text).
std::uint64_t digest(const std::string& s) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (unsigned char c : s) {
    h ^= c;
    h *= 0x100000001b3ull;
  }
  return h;
}

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = text.find('\n', start);
    const std::string line = text.substr(start, end == std::string::npos ? std::string::npos : end - start);
    if (!line.empty() && line[0] != '#') lines.push_back(line);
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return lines;
}

// "key: value" lines with two-space nesting (to_yaml's layout) as
// ("fiber.eta", "1.55") pairs: the dotted path names the field in messages.
struct Field {
  std::string key, value;
};
std::vector<Field> fields_of(const std::vector<std::string>& lines) {
  std::vector<Field> out;
  std::string section;
  for (const std::string& line : lines) {
    const bool nested = line.rfind("  ", 0) == 0;
    const std::size_t start = line.find_first_not_of(' ');
    const std::string body = start == std::string::npos ? "" : line.substr(start);
    const std::size_t colon = body.find(':');
    const std::string key = body.substr(0, colon);
    std::string value;
    if (colon != std::string::npos) {
      const std::size_t v = body.find_first_not_of(' ', colon + 1);
      if (v != std::string::npos) value = body.substr(v);
    }
    if (!nested) section = value.empty() ? key : "";
    out.push_back({nested && !section.empty() ? section + "." + key : key, value});
  }
  return out;
}

std::string shown(std::string value) {
  if (value.empty()) return "(none)";
  if (value.size() > 80) value = value.substr(0, 77) + "...";
  return value;
}

}  // namespace

std::string run_agreement_text(const Settings& settings, double target_error,
                               const RunProgress* resumed) {
  std::string text = to_yaml(settings);
  text += fmt::format("target_error: {}\n", target_error);
  if (resumed) {
    // The progress digest stands for every direction's next photon and done
    // flag (5e5 directions would make a long line).
    std::string progress;
    std::uint64_t traced = 0;
    for (std::size_t k = 0; k < resumed->next_photon.size(); ++k) {
      progress += fmt::format("{}:{},", resumed->next_photon[k], int{resumed->done[k]});
      traced += resumed->next_photon[k];
    }
    text += fmt::format("checkpoint: {} photons started, progress digest {:016x}\n", traced,
                        digest(progress));
  } else {
    text += "checkpoint: none (a new run)\n";
  }
  return text;
}

std::optional<std::string> ranks_disagree(const ProcessGroup& group, const std::string& text) {
  if (group.size() == 1) return std::nullopt;
  const std::vector<std::string> lines = split_lines(text);
  std::vector<std::uint64_t> root_digests(lines.size());
  for (std::size_t i = 0; i < lines.size(); ++i) root_digests[i] = digest(lines[i]);
  const std::vector<std::uint64_t> mine = root_digests;
  group.broadcast(root_digests);  // rank 0's, on every rank
  // This rank's first differing field, as "INDEX\nKEY\nVALUE" (the line
  // index, then its dotted key and value: rank 0 adds its own value).
  const std::vector<Field> fields = fields_of(lines);
  std::optional<std::string> differing;
  const std::size_t common = std::min(mine.size(), root_digests.size());
  for (std::size_t i = 0; i <= common && !differing; ++i) {
    if (i == common ? mine.size() == root_digests.size() : mine[i] == root_digests[i]) continue;
    differing = i < fields.size() ? fmt::format("{}\n{}\n{}", i, fields[i].key, fields[i].value)
                                  : fmt::format("{}\n(a field rank 0 has)\n", i);
  }
  const std::optional<ProcessGroup::RankMessage> first = group.first_message(differing);
  if (!first) return std::nullopt;
  const std::string& m = first->text;
  const std::size_t a = m.find('\n'), b = m.find('\n', a + 1);
  const std::size_t index = std::stoull(m.substr(0, a));
  std::string key = m.substr(a + 1, b - a - 1);
  if (index < fields.size() && key.front() == '(') key = fields[index].key;
  const std::string root_value = index < fields.size() ? fields[index].value : "";
  return fmt::format("rank {} was started with another config or flags than rank 0: {} = {} on "
                     "rank {}, {} on rank 0 (every rank must be given the same config file and "
                     "flags; only --threads, --quiet and --checkpoint-every may differ)",
                     first->rank, key, shown(m.substr(b + 1)), first->rank, shown(root_value));
}

}  // namespace fiberlab::sim
