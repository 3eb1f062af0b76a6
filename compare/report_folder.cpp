#include "compare/report_folder.h"

#include <dirent.h>
#include <fcntl.h>
#include <fmt/core.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <vector>

#include "common/error.h"

namespace fiberlab::compare {

namespace fs = std::filesystem;

namespace {

constexpr const char* kStagingPrefix = ".report-staging-";

[[noreturn]] void refuse(const std::string& dir, const std::string& why) {
  throw Error(fmt::format("--report {}: {}", dir, why));
}

const char* kind_of(mode_t mode) {
  if (S_ISLNK(mode)) return "a symbolic link";
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  return "not a regular file";
}

// The entries of a folder (not . and ..), sorted.
std::vector<std::string> entries(const std::string& dir) {
  std::vector<std::string> out;
  DIR* d = opendir(dir.c_str());
  if (!d) return out;
  while (const dirent* e = readdir(d)) {
    const std::string name = e->d_name;
    if (name != "." && name != "..") out.push_back(name);
  }
  closedir(d);
  std::sort(out.begin(), out.end());
  return out;
}

// Staging folders .report-staging-PID.XXXXXX in DIR whose process is gone.
void remove_stale_staging(const std::string& dir) {
  const std::string prefix = kStagingPrefix;
  for (const std::string& name : entries(dir)) {
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::size_t dot = name.find('.', prefix.size());
    const std::string digits = name.substr(prefix.size(), dot == std::string::npos ? 0 : dot - prefix.size());
    if (digits.empty() || digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos)
      continue;
    const pid_t pid = static_cast<pid_t>(std::stol(digits));
    if (pid == getpid() || kill(pid, 0) == 0 || errno != ESRCH) continue;
    const fs::path p = fs::path(dir) / name;
    struct stat st {};
    // A real folder only (remove_all removes links inside, never their targets).
    if (lstat(p.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) {
      std::error_code ec;
      fs::remove_all(p, ec);
    }
  }
}

void fsync_dir(const std::string& dir) {
  const int fd = open(dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (fd < 0) return;
  fsync(fd);  // best effort: the files themselves were flushed by their writers
  close(fd);
}

}  // namespace

void check_report_dir_possible(const std::string& dir) {
  if (dir.empty()) throw Error("--report: the folder name is empty");
  fs::path p = fs::absolute(dir);
  std::error_code ec;
  while (!fs::exists(fs::symlink_status(p, ec)) && p.has_parent_path() && p != p.parent_path())
    p = p.parent_path();
  if (!fs::is_directory(p, ec))
    refuse(dir, fmt::format("{} exists and is not a folder", p.string()));
  if (access(p.c_str(), W_OK | X_OK) != 0) refuse(dir, fmt::format("folder {} is not writable", p.string()));
}

ReportFolder::ReportFolder(std::string dir) : dir_(std::move(dir)) {
  check_report_dir_possible(dir_);
  std::error_code ec;
  if (!fs::exists(dir_, ec)) {
    fs::path top = fs::absolute(dir_);
    while (top.has_parent_path() && !fs::exists(top.parent_path(), ec)) top = top.parent_path();
    fs::create_directories(dir_, ec);
    if (ec || !fs::is_directory(dir_))
      refuse(dir_, fmt::format("cannot create the folder ({})", ec.message()));
    created_ = top.string();
  }
  if (!fs::is_directory(dir_, ec)) refuse(dir_, "exists and is not a folder");
  remove_stale_staging(dir_);
  std::string pattern = (fs::path(dir_) / fmt::format("{}{}.XXXXXX", kStagingPrefix, getpid())).string();
  if (!mkdtemp(pattern.data())) refuse(dir_, fmt::format("cannot create a folder in it: {}", std::strerror(errno)));
  staging_ = pattern;
}

ReportFolder::~ReportFolder() {
  if (committed_) return;
  std::error_code ec;
  fs::remove_all(staging_, ec);
  // Only folders this made, and only while empty (fs::remove on a folder is rmdir).
  if (!created_.empty()) {
    for (fs::path p = fs::absolute(dir_);; p = p.parent_path()) {
      if (!fs::remove(p, ec)) break;
      if (p == fs::path(created_) || !p.has_parent_path()) break;
    }
  }
}

void ReportFolder::rethrow(const std::exception& e) const {
  std::string message = e.what();
  for (std::size_t at; (at = message.find(staging_)) != std::string::npos;)
    message.replace(at, staging_.size(), dir_);
  throw Error(message);
}

void ReportFolder::commit() {
  // The report's files: not a temporary a failed writer left (NAME.tmp of
  // the plotting script, .NAME.tmp-PID of AtomicOutput), which stays to be
  // removed with the staging folder.
  std::vector<std::string> names;
  for (const std::string& name : entries(staging_))
    if (name[0] != '.' && !name.ends_with(".tmp")) names.push_back(name);
  // Every name first, so that a refusal moves nothing.
  for (const std::string& name : names) {
    struct stat st {};
    const fs::path staged = fs::path(staging_) / name;
    if (lstat(staged.c_str(), &st) != 0 || !S_ISREG(st.st_mode))
      refuse(dir_, fmt::format("the report's {} is not a regular file (the plotting script made {})", name,
                               kind_of(st.st_mode)));
    const fs::path target = fs::path(dir_) / name;
    if (lstat(target.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
      refuse(dir_, fmt::format("{} is {}; the report's files must be regular files or not exist yet "
                               "(remove it, or give another --report folder)",
                               name, kind_of(st.st_mode)));
  }
  const bool page = std::find(names.begin(), names.end(), "report.html") != names.end();
  for (const std::string& name : names) {
    const fs::path staged = fs::path(staging_) / name, target = fs::path(dir_) / name;
    if (std::rename(staged.c_str(), target.c_str()) != 0)
      refuse(dir_, fmt::format("cannot move {} into place: {}", name, std::strerror(errno)));
  }
  // A page describing an earlier report (unlink removes a link, not its target).
  if (!page) unlink((fs::path(dir_) / "report.html").c_str());
  committed_ = true;
  std::error_code ec;
  fs::remove_all(staging_, ec);
  fsync_dir(dir_);
}

}  // namespace fiberlab::compare
