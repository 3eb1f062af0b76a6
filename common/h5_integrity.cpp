#include "common/h5_integrity.h"

#include <fcntl.h>
#include <fmt/core.h>
#include <poll.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <vector>

#include "common/error.h"

namespace fiberlab::h5 {

namespace {

// An attribute value larger than this is refused (a damaged or crafted file
// can declare any size).
constexpr std::uint64_t kMaxAttributeBytes = std::uint64_t{64} << 20;

// Closes an HDF5 id on scope exit.
struct Id {
  hid_t id;
  herr_t (*close)(hid_t);
  ~Id() {
    if (id >= 0) close(id);
  }
};

[[noreturn]] void unreadable(const std::string& path, const std::string& what) {
  throw Error(fmt::format("{}: damaged or unreadable HDF5 file: cannot read {}", path, what));
}

class Fnv1a {
 public:
  void add(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) h_ = (h_ ^ p[i]) * 0x100000001b3ULL;
  }
  void add(const std::string& s) { add(s.c_str(), s.size() + 1); }  // with its NUL: a separator
  std::uint64_t value() const { return h_; }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ULL;
};

herr_t collect_link(hid_t, const char* name, const H5L_info_t* info, void* out) {
  if (info->type == H5L_TYPE_HARD) static_cast<std::vector<std::string>*>(out)->push_back(name);
  return 0;
}

herr_t collect_attr(hid_t, const char* name, const H5A_info_t*, void* out) {
  static_cast<std::vector<std::string>*>(out)->push_back(name);
  return 0;
}

// "/" and every object under it reached by a hard link, in name order.
std::vector<std::string> object_paths(hid_t file, const std::string& path) {
  std::vector<std::string> names;
  if (H5Lvisit(file, H5_INDEX_NAME, H5_ITER_INC, collect_link, &names) < 0)
    unreadable(path, "its links");
  std::vector<std::string> paths{"/"};
  for (const std::string& n : names) paths.push_back("/" + n);
  return paths;
}

void digest_attribute(hid_t obj, const std::string& obj_path, const std::string& name,
                      const std::string& path, Fnv1a& h) {
  const std::string what = obj_path + "@" + name;
  Id a{H5Aopen(obj, name.c_str(), H5P_DEFAULT), H5Aclose};
  if (a.id < 0) unreadable(path, what);
  Id type{H5Aget_type(a.id), H5Tclose};
  Id space{H5Aget_space(a.id), H5Sclose};
  if (type.id < 0 || space.id < 0) unreadable(path, what);
  const hssize_t n = H5Sget_simple_extent_npoints(space.id);
  const H5T_class_t cls = H5Tget_class(type.id);
  if (n < 0 || cls < 0) unreadable(path, what);
  h.add(obj_path);
  h.add(name);
  const unsigned char cls_byte = static_cast<unsigned char>(cls);
  h.add(&cls_byte, 1);
  if (cls == H5T_STRING && H5Tis_variable_str(type.id) > 0) {
    if (static_cast<std::uint64_t>(n) > kMaxAttributeBytes / sizeof(char*)) unreadable(path, what);
    Id mem{H5Tcopy(H5T_C_S1), H5Tclose};
    H5Tset_size(mem.id, H5T_VARIABLE);
    H5Tset_cset(mem.id, H5Tget_cset(type.id));
    std::vector<char*> p(static_cast<std::size_t>(n), nullptr);
    if (n > 0 && H5Aread(a.id, mem.id, p.data()) < 0) unreadable(path, what);
    for (char* s : p) h.add(std::string(s ? s : ""));
    if (n > 0) H5Dvlen_reclaim(mem.id, space.id, H5P_DEFAULT, p.data());
    return;
  }
  if (cls == H5T_STRING || cls == H5T_INTEGER || cls == H5T_FLOAT) {
    Id mem{cls == H5T_STRING ? H5Tcopy(type.id) : H5Tget_native_type(type.id, H5T_DIR_ASCEND),
           H5Tclose};
    const std::size_t size = mem.id < 0 ? 0 : H5Tget_size(mem.id);
    if (size == 0 || static_cast<std::uint64_t>(n) > kMaxAttributeBytes / size)
      unreadable(path, what);
    std::vector<unsigned char> bytes(size * static_cast<std::size_t>(n));
    if (n > 0 && H5Aread(a.id, mem.id, bytes.data()) < 0) unreadable(path, what);
    h.add(bytes.data(), bytes.size());
  }
  // Other classes (fiberlab writes none): the name and class only.
}

// Every dataset of at most kProbeDatasetBytes read whole (checksums and
// inflate run on it); larger ones are left to their readers.
void read_dataset(hid_t file, const std::string& name, const std::string& path) {
  Id set{H5Dopen2(file, name.c_str(), H5P_DEFAULT), H5Dclose};
  if (set.id < 0) unreadable(path, name);
  Id type{H5Dget_type(set.id), H5Tclose};
  Id space{H5Dget_space(set.id), H5Sclose};
  if (type.id < 0 || space.id < 0) unreadable(path, name);
  const H5T_class_t cls = H5Tget_class(type.id);
  if (cls != H5T_INTEGER && cls != H5T_FLOAT) return;
  const hssize_t n = H5Sget_simple_extent_npoints(space.id);
  Id mem{H5Tget_native_type(type.id, H5T_DIR_ASCEND), H5Tclose};
  const std::size_t size = mem.id < 0 ? 0 : H5Tget_size(mem.id);
  if (n < 0 || size == 0) unreadable(path, name);
  if (static_cast<std::uint64_t>(n) > kProbeDatasetBytes / size) return;
  std::vector<unsigned char> bytes(size * static_cast<std::size_t>(n));
  if (n > 0 && H5Dread(set.id, mem.id, H5S_ALL, H5S_ALL, H5P_DEFAULT, bytes.data()) < 0)
    unreadable(path, name);
}

std::uint64_t stored_digest(hid_t file, const std::string& path) {
  Id a{H5Aopen(file, kDigestAttribute, H5P_DEFAULT), H5Aclose};
  std::uint64_t v = 0;
  if (a.id < 0 || H5Aread(a.id, H5T_NATIVE_UINT64, &v) < 0)
    unreadable(path, std::string("/@") + kDigestAttribute);
  return v;
}

// probe_file's work, in whichever process runs it. Returns false when the
// file does not open as HDF5 (its reader says so in its own words).
bool check_file(const std::string& path) {
  Id file{H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose};
  if (file.id < 0) return false;
  const std::uint64_t digest = attribute_digest(file.id, path);
  for (const std::string& obj : object_paths(file.id, path)) {
    Id o{H5Oopen(file.id, obj.c_str(), H5P_DEFAULT), H5Oclose};
    if (o.id < 0) unreadable(path, obj);
    if (H5Iget_type(o.id) == H5I_DATASET) read_dataset(file.id, obj, path);
  }
  const htri_t has = H5Aexists(file.id, kDigestAttribute);
  if (has < 0) unreadable(path, std::string("/@") + kDigestAttribute);
  if (has > 0 && stored_digest(file.id, path) != digest)
    throw Error(fmt::format("{}: damaged file: its attributes do not match the digest fiberlab "
                            "stored with them (root attribute {}); it was altered after it "
                            "was written",
                            path, kDigestAttribute));
  return true;
}

}  // namespace

std::uint64_t attribute_digest(hid_t file, const std::string& path) {
  Fnv1a h;
  for (const std::string& obj : object_paths(file, path)) {
    Id o{H5Oopen(file, obj.c_str(), H5P_DEFAULT), H5Oclose};
    if (o.id < 0) unreadable(path, obj);
    std::vector<std::string> names;
    hsize_t idx = 0;
    if (H5Aiterate2(o.id, H5_INDEX_NAME, H5_ITER_INC, &idx, collect_attr, &names) < 0)
      unreadable(path, "the attributes of " + obj);
    for (const std::string& name : names)
      if (!(obj == "/" && name == kDigestAttribute)) digest_attribute(o.id, obj, name, path, h);
  }
  return h.value();
}

void probe_file(const std::string& path) {
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) {  // no isolation possible: check here
    check_file(path);
    return;
  }
  const pid_t pid = fork();
  if (pid < 0) {
    close(fds[0]);
    close(fds[1]);
    check_file(path);
    return;
  }
  if (pid == 0) {
    // The child: nothing it prints is the caller's (a sanitizer's report of
    // a crash inside HDF5 included); only the error line goes to the pipe.
    // _exit: no exit-time cleanup of the parent's state (its open files).
    close(fds[0]);
    const int null = open("/dev/null", O_WRONLY);
    if (null >= 0) {
      dup2(null, STDOUT_FILENO);
      dup2(null, STDERR_FILENO);
    }
    int status = 0;
    std::string message;
    try {
      check_file(path);
    } catch (const std::exception& e) {
      message = e.what();
      status = 3;
    }
    for (std::size_t done = 0; done < message.size();) {
      const ssize_t w = write(fds[1], message.data() + done, message.size() - done);
      if (w <= 0) break;
      done += static_cast<std::size_t>(w);
    }
    _exit(status);
  }
  close(fds[1]);
  // Damaged metadata can also make HDF5 loop forever (a B-tree or free-space
  // list pointing back into itself: found by the bit-flip fuzz): the child
  // gets kProbeSeconds plus a second per 20 MB of file, then is killed.
  struct stat st {};
  const double size = stat(path.c_str(), &st) == 0 ? static_cast<double>(st.st_size) : 0.0;
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration<double>(kProbeSeconds + size / 20e6);
  std::string message;
  char buf[4096];
  bool timed_out = false;
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline -
                                                                            std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      timed_out = true;
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    const int ready = poll(&p, 1, static_cast<int>(std::min<long long>(left.count(), 1000)));
    if (ready < 0 && errno != EINTR) break;
    if (ready <= 0) continue;
    const ssize_t r = read(fds[0], buf, sizeof buf);
    if (r > 0) {
      message.append(buf, static_cast<std::size_t>(r));
    } else if (r == 0 || errno != EINTR) {
      break;
    }
  }
  close(fds[0]);
  if (timed_out) kill(pid, SIGKILL);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (timed_out)
    throw Error(fmt::format("{}: damaged HDF5 file: reading its metadata did not finish in {:.0f} s "
                            "(the HDF5 library loops on it)",
                            path, kProbeSeconds + size / 20e6));
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
  if (WIFEXITED(status) && WEXITSTATUS(status) == 3 && !message.empty()) throw Error(message);
  throw Error(fmt::format("{}: damaged HDF5 file: reading its metadata crashed the HDF5 library ({})",
                          path,
                          WIFSIGNALED(status) ? fmt::format("signal {}", WTERMSIG(status))
                                              : fmt::format("exit {}", WEXITSTATUS(status))));
}

}  // namespace fiberlab::h5
