#include "common/atomic_output.h"

#include <dirent.h>
#include <fcntl.h>
#include <fmt/core.h>
#include <sys/stat.h>
#include <unistd.h>

#include <climits>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "common/error.h"

namespace fiberlab {

namespace fs = std::filesystem;

namespace {

std::string folder_of(const std::string& target) {
  const fs::path p(target);
  return p.has_parent_path() ? p.parent_path().string() : std::string(".");
}

const char* file_kind(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISLNK(mode)) return "a symbolic link";
  return "not a regular file";
}

[[noreturn]] void refuse(const std::string& target, const std::string& why) {
  throw Error(fmt::format("output: {}: {}", target, why));
}

void check_not_an_input(const std::string& target, const struct stat& out,
                        const std::vector<std::string>& inputs) {
  for (const std::string& in : inputs) {
    struct stat st {};
    if (stat(in.c_str(), &st) == 0 && st.st_dev == out.st_dev && st.st_ino == out.st_ino)
      refuse(target, fmt::format("is the input file {} (it would be overwritten; give another "
                                 "output path)", in));
  }
}

// .NAME.tmp-PID files of this target whose process is gone (regular files
// only: a symbolic link of that name is left, never followed).
void remove_stale_in(const std::string& dir, const std::string& name) {
  const std::string prefix = "." + name + ".tmp-";
  DIR* d = opendir(dir.c_str());
  if (!d) return;
  while (const dirent* e = readdir(d)) {
    const std::string entry = e->d_name;
    if (entry.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string digits = entry.substr(prefix.size());
    if (digits.empty() || digits.size() > 9 ||
        digits.find_first_not_of("0123456789") != std::string::npos)
      continue;
    const pid_t pid = static_cast<pid_t>(std::stol(digits));
    if (pid == getpid()) continue;
    if (kill(pid, 0) == 0 || errno != ESRCH) continue;  // alive, or not ours to judge
    const std::string stale = (fs::path(dir) / entry).string();
    struct stat st {};
    if (lstat(stale.c_str(), &st) == 0 && S_ISREG(st.st_mode)) unlink(stale.c_str());
  }
  closedir(d);
}

void fsync_path(const std::string& path, int flags, const std::string& target, const char* what) {
  const int fd = open(path.c_str(), flags);
  if (fd < 0) refuse(target, fmt::format("cannot open {} to flush it: {}", what, std::strerror(errno)));
  const int rc = fsync(fd);
  const int err = errno;
  close(fd);
  // Folders on some file systems do not support fsync (EINVAL): nothing to flush there.
  if (rc != 0 && !(err == EINVAL && (flags & O_DIRECTORY)))
    refuse(target, fmt::format("cannot flush {} to disk: {}", what, std::strerror(err)));
}

}  // namespace

void check_output_name(const std::string& target) {
  std::string shown;  // the path on one line: control characters as \xNN
  bool control = false;
  for (unsigned char c : target) {
    control = control || c < 0x20 || c == 0x7f;
    shown += c < 0x20 || c == 0x7f ? fmt::format("\\x{:02x}", c) : std::string(1, static_cast<char>(c));
  }
  if (control)
    throw Error(fmt::format("output: {}: the path contains a control character (newline, tab, ...); "
                            "give a name without control characters", shown));
  // The longest name made from it: the temporary .NAME.tmp-PID, the PID up
  // to 7 digits (Linux's pid_max is at most 2^22).
  constexpr std::size_t kTempExtra = 1 + 5 + 7;  // ".", ".tmp-", PID
  const std::string name = fs::path(target).filename().string();
  long name_max = pathconf(folder_of(target).c_str(), _PC_NAME_MAX);
  if (name_max <= 0) name_max = NAME_MAX;
  if (name.size() + kTempExtra > static_cast<std::size_t>(name_max))
    refuse(target, fmt::format("the file name is {} bytes; its temporary name .NAME.tmp-PID would exceed "
                               "the folder's limit of {} bytes per name (NAME_MAX): give a name of at "
                               "most {} bytes", name.size(), name_max, name_max - static_cast<long>(kTempExtra)));
  if (target.size() + kTempExtra >= PATH_MAX)
    refuse(target, fmt::format("the path is {} bytes; with its temporary name it would exceed the "
                               "limit of {} bytes per path (PATH_MAX)", target.size(), PATH_MAX));
}

void check_output_target(const std::string& target, const std::vector<std::string>& inputs) {
  if (target.empty()) throw Error("output: the output path is empty (give a file name)");
  check_output_name(target);
  const std::string dir = folder_of(target);
  struct stat st {};
  if (stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode))
    refuse(target, fmt::format("folder {} does not exist", dir));
  if (access(dir.c_str(), W_OK) != 0)
    refuse(target, fmt::format("folder {} is not writable", dir));
  if (lstat(target.c_str(), &st) != 0) {
    if (errno == ENOENT) return;
    refuse(target, fmt::format("cannot inspect: {}", std::strerror(errno)));
  }
  if (!S_ISREG(st.st_mode))
    refuse(target, fmt::format("is {}; the output must be a regular file or not exist yet",
                               file_kind(st.st_mode)));
  // The mode bits, not access(): root may write anything, but a file made
  // read-only by its owner is not to be replaced.
  if ((st.st_mode & (S_IWUSR | S_IWGRP | S_IWOTH)) == 0 || access(target.c_str(), W_OK) != 0)
    refuse(target, "exists and is read-only (remove it or make it writable to replace it)");
  check_not_an_input(target, st, inputs);
}

AtomicOutput::AtomicOutput(std::string target, const std::vector<std::string>& inputs)
    : target_(std::move(target)) {
  check_output_target(target_, inputs);
  dir_ = folder_of(target_);
  const std::string name = fs::path(target_).filename().string();
  remove_stale_in(dir_, name);
  temp_ = (fs::path(dir_) / fmt::format(".{}.tmp-{}", name, getpid())).string();
  // The temporary's name is predictable: whatever is there already (a link
  // planted to make the writer truncate another file, or the file of a dead
  // process of the same id) is removed (unlink removes a link, not its
  // target), and the file is made here, new and never through a link
  // (O_EXCL | O_NOFOLLOW), before any writer (HDF5, an ofstream) opens it.
  guard_.emplace(temp_);
  unlink(temp_.c_str());
  const int fd = open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
  if (fd < 0)
    refuse(target_, fmt::format("cannot create its temporary file {}: {}", temp_, std::strerror(errno)));
  close(fd);
}

void remove_stale_temporaries(const std::string& target) {
  if (target.empty()) return;
  remove_stale_in(folder_of(target), fs::path(target).filename().string());
}

AtomicOutput::~AtomicOutput() {
  if (!committed_) std::remove(temp_.c_str());
}

void AtomicOutput::commit() {
  fsync_path(temp_, O_RDONLY, target_, "the temporary file");
  if (std::rename(temp_.c_str(), target_.c_str()) != 0)
    refuse(target_, fmt::format("cannot rename the finished file: {}", std::strerror(errno)));
  committed_ = true;
  guard_.reset();
  fsync_path(dir_, O_RDONLY | O_DIRECTORY, target_, "its folder");
}

}  // namespace fiberlab
