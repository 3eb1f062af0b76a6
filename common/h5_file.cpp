#include "common/h5_file.h"

#include <fmt/core.h>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstring>
#include <mutex>
#include <thread>

#include <cmath>

#include "common/error.h"
#include "common/h5_integrity.h"

namespace fiberlab::h5 {

namespace {

// A fixed-length string attribute longer than this is refused before it is
// read (a crafted file can declare any length).
constexpr std::size_t kMaxStringBytes = 64u << 20;

std::string shape_text(const Dims& dims) {
  if (dims.empty()) return "a scalar";
  std::string s;
  for (std::size_t i = 0; i < dims.size(); ++i) s += fmt::format("{}{}", i ? " x " : "", dims[i]);
  return s;
}

// A failed write usually comes from the system (errno ENOSPC: disk full,
// EDQUOT, EIO): say so when errno was set.
void check(herr_t status, const std::string& what, const std::string& path) {
  if (status >= 0) return;
  if (errno != 0)
    throw Error(fmt::format("{}: HDF5 error: {}: {}", path, what, std::strerror(errno)));
  throw Error(fmt::format("{}: HDF5 error: {}", path, what));
}

// Frees the disk space of a file being written whose write failed (always a
// temporary that AtomicOutput removes; its contents are lost anyway). Why:
// HDF5 still flushes its chunk and metadata caches when the dataset and the
// file are closed, which fails again on a full disk; HDF5 1.10 then keeps the
// id of an object whose close failed although the object is freed, and the
// library cleanup at exit (H5close, which the HDF5 C++ library linked into
// fiberlab calls from a static destructor whatever H5dont_atexit says) closes
// that id again: a segfault in H5F__close_cb after the error was printed.
// With the space freed first, every later close succeeds and no id is left.
void drop_contents(hid_t file) {
  void* handle = nullptr;
  if (H5Fget_vfd_handle(file, H5P_DEFAULT, &handle) >= 0 && handle)
    if (ftruncate(*static_cast<int*>(handle), 0) != 0) { /* the close reports */ }
}

// check() for a write into `file`: on failure the file's contents are
// dropped (drop_contents) before the exception unwinds the open ids.
void check_write(herr_t status, hid_t file, const std::string& what, const std::string& path) {
  if (status >= 0) return;
  const int err = errno;
  drop_contents(file);
  errno = err;
  check(status, what, path);
}

Handle checked(hid_t id, Handle::Closer closer, const std::string& what, const std::string& path) {
  if (id < 0) throw Error(fmt::format("{}: HDF5 error: {}", path, what));
  return Handle(id, closer);
}

Handle open_object(hid_t file, const std::string& obj, const std::string& path) {
  return checked(H5Oopen(file, obj.c_str(), H5P_DEFAULT), H5Oclose, "cannot open " + obj, path);
}

Handle open_attr(hid_t file, const std::string& obj, const std::string& name,
                 const std::string& path) {
  return checked(H5Aopen_by_name(file, obj.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT),
                 H5Aclose, "missing attribute " + obj + "@" + name, path);
}

// Large arrays are chunked and compressed (most histogram bins are empty),
// with chunks of at most 65536 cells. `slab_rows`: a chunk never spans two
// slabs along the first dimension (slab-at-a-time writing), nor two rows
// along the second when a row holds at least 4096 cells (a lobe of bins: the
// rows that File::plan_rows compresses on any thread).
Dims chunk_shape(const Dims& dims, bool slab_rows) {
  Dims chunk = dims;
  hsize_t cells = 1;
  for (hsize_t d : dims) cells *= d;
  std::size_t i = 0;
  if (slab_rows) {
    cells /= chunk[0];
    chunk[0] = 1;
    i = 1;
    if (chunk.size() > 2 && cells / chunk[1] >= 4096) {
      cells /= chunk[1];
      chunk[1] = 1;
      i = 2;
    }
  }
  // The leading dimensions split until a chunk holds at most 65536 cells.
  for (; i < chunk.size() && cells > 65536; ++i) {
    cells /= chunk[i];
    chunk[i] = 1;
    if (cells < 65536) {
      chunk[i] = std::min(dims[i], std::max<hsize_t>(1, 65536 / std::max<hsize_t>(cells, 1)));
      break;
    }
  }
  return chunk;
}

Handle dataset_creation(const Dims& dims, bool slab_rows, const std::string& path) {
  hsize_t n = 1;
  for (hsize_t d : dims) n *= d;
  Handle dcpl = checked(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, "property list", path);
  if (n > 0 && n < 4096 && !slab_rows && !dims.empty() &&
      H5Zfilter_avail(H5Z_FILTER_FLETCHER32) > 0) {
    // Small datasets (the ledger, photons, angles) in one chunk with a
    // Fletcher-32 checksum, so that damage to their values is an HDF5 read
    // error (common/h5_integrity.h); deflated ones are checked by inflate.
    H5Pset_chunk(dcpl.id(), static_cast<int>(dims.size()), dims.data());
    H5Pset_fletcher32(dcpl.id());
  } else if ((n >= 4096 || slab_rows) && !dims.empty() && n > 0 &&
      H5Zfilter_avail(H5Z_FILTER_DEFLATE) > 0) {
    const Dims chunk = chunk_shape(dims, slab_rows);
    H5Pset_chunk(dcpl.id(), static_cast<int>(chunk.size()), chunk.data());
    // Level 2: libdeflate (the row plans' compressor) deflates zeros and
    // sparse bins faster at level 2 than at level 1, into files no larger;
    // higher levels are slower.
    H5Pset_deflate(dcpl.id(), 2);
  }
  return dcpl;
}

// The deflate level of a chunked layout whose only filter is deflate (what
// dataset_creation makes of a dataset of 4096 cells or more), or -1: then
// fiberlab can deflate its chunks itself and hand them over as stored.
int only_deflate_level(hid_t dcpl) {
  if (H5Pget_layout(dcpl) != H5D_CHUNKED || H5Pget_nfilters(dcpl) != 1) return -1;
  unsigned flags = 0, cd[4] = {0, 0, 0, 0};
  std::size_t n_cd = 4;
  if (H5Pget_filter2(dcpl, 0, &flags, &n_cd, cd, 0, nullptr, nullptr) != H5Z_FILTER_DEFLATE ||
      n_cd < 1)
    return -1;
  return static_cast<int>(cd[0]);
}

// The chunk dimensions of a chunked layout of rank `rank` (empty if not).
Dims chunk_dims(hid_t dcpl, std::size_t rank) {
  Dims chunk(rank);
  if (H5Pget_chunk(dcpl, static_cast<int>(rank), chunk.data()) != static_cast<int>(rank)) return {};
  return chunk;
}

template <typename T>
void write_dataset(hid_t file, const std::string& path, const std::string& name,
                   const Dims& dims, const std::vector<T>& data, hid_t mem_type, hid_t file_type) {
  hsize_t n = 1;
  for (hsize_t d : dims) n *= d;
  if (n != data.size())
    throw Error(fmt::format("{}: internal error: {} has {} values for {} cells", path, name,
                            data.size(), n));
  Handle space = checked(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr),
                         H5Sclose, "dataspace for " + name, path);
  Handle dcpl = dataset_creation(dims, false, path);
  Handle set = checked(H5Dcreate2(file, name.c_str(), file_type, space.id(), H5P_DEFAULT,
                                  dcpl.id(), H5P_DEFAULT),
                       H5Dclose, "cannot create " + name, path);
  errno = 0;
  const int level = only_deflate_level(dcpl.id());
  if (level >= 0 && chunk_dims(dcpl.id(), dims.size()) == dims && sizeof(T) == 8 &&
      std::endian::native == std::endian::little) {
    // One chunk, deflated here by libdeflate (common/deflater.h) and handed
    // over as it is stored: HDF5's own zlib filter took about 1 ms for the
    // 16,200 solid angles of a 90 x 180 grid, libdeflate a tenth of that.
    // (The file types are the little-endian forms of T.)
    std::vector<unsigned char> chunk;
    const std::size_t bytes = data.size() * sizeof(T);
    thread_deflater(level).deflate(reinterpret_cast<const unsigned char*>(data.data()), bytes, bytes,
                                   chunk);
    const Dims origin(dims.size(), 0);
    check_write(H5Dwrite_chunk(set.id(), H5P_DEFAULT, 0, origin.data(), chunk.size(), chunk.data()),
                file, "cannot write " + name, path);
  } else {
    check_write(H5Dwrite(set.id(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()), file,
                "cannot write " + name, path);
  }
  // Written to disk now, while a failure can still drop the file's contents
  // (the close of `set` would flush it with no way to report a failure).
  check_write(H5Dflush(set.id()), file, "cannot write " + name, path);
}

// Reads or writes the block of a dataset at leading indices `at` (one index:
// slab at[0] along the first dimension; two: its row at[1] along the second).
template <typename T>
void slab_io(hid_t file, const std::string& path, const std::string& name, const Dims& at,
             std::vector<T>* read_into, const std::vector<T>* write_from, hid_t mem_type) {
  Handle set = checked(H5Dopen2(file, name.c_str(), H5P_DEFAULT), H5Dclose, "missing " + name,
                       path);
  Handle space = checked(H5Dget_space(set.id()), H5Sclose, "dataspace of " + name, path);
  const int rank = H5Sget_simple_extent_ndims(space.id());
  if (rank < static_cast<int>(at.size()))
    throw Error(fmt::format("{}: {} is not an array of rank >= {}", path, name, at.size()));
  Dims dims(rank);
  H5Sget_simple_extent_dims(space.id(), dims.data(), nullptr);
  Dims start(rank, 0), count = dims;
  for (std::size_t d = 0; d < at.size(); ++d) {
    if (at[d] >= dims[d])
      throw Error(fmt::format("{}: {} has {} entries along dimension {}, not {}", path, name,
                              dims[d], d, at[d] + 1));
    start[d] = at[d];
    count[d] = 1;
  }
  hsize_t n = 1;
  for (hsize_t d : count) n *= d;
  check(H5Sselect_hyperslab(space.id(), H5S_SELECT_SET, start.data(), nullptr, count.data(),
                            nullptr),
        "select slab of " + name, path);
  // The memory space has the selection's shape: a flat one makes HDF5 map
  // cells one run at a time (H5S_select_iterate), a third of a run's writing.
  Handle mem = checked(H5Screate_simple(rank, count.data(), nullptr), H5Sclose, "memory space", path);
  if (read_into) {
    read_into->resize(n);
    check(H5Dread(set.id(), mem_type, mem.id(), space.id(), H5P_DEFAULT, read_into->data()),
          "cannot read " + name, path);
  } else {
    if (write_from->size() != n)
      throw Error(fmt::format("{}: internal error: slab of {} has {} values for {} cells", path,
                              name, write_from->size(), n));
    errno = 0;
    check_write(H5Dwrite(set.id(), mem_type, mem.id(), space.id(), H5P_DEFAULT, write_from->data()),
                file, "cannot write " + name, path);
    check_write(H5Dflush(set.id()), file, "cannot write " + name, path);
  }
}

template <typename T>
std::vector<T> read_dataset(hid_t file, const std::string& path, const std::string& name,
                            Dims* dims_out, hid_t mem_type) {
  Handle set = checked(H5Dopen2(file, name.c_str(), H5P_DEFAULT), H5Dclose, "missing " + name,
                       path);
  Handle space = checked(H5Dget_space(set.id()), H5Sclose, "dataspace of " + name, path);
  const int rank = H5Sget_simple_extent_ndims(space.id());
  Dims dims(rank);
  H5Sget_simple_extent_dims(space.id(), dims.data(), nullptr);
  hsize_t n = 1;
  for (hsize_t d : dims) n *= d;
  std::vector<T> data(n);
  check(H5Dread(set.id(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()),
        "cannot read " + name, path);
  if (dims_out) *dims_out = dims;
  return data;
}

Dims dataset_shape(hid_t file, const std::string& path, const std::string& name) {
  Handle set = checked(H5Dopen2(file, name.c_str(), H5P_DEFAULT), H5Dclose, "missing " + name,
                       path);
  Handle space = checked(H5Dget_space(set.id()), H5Sclose, "dataspace of " + name, path);
  const int rank = H5Sget_simple_extent_ndims(space.id());
  if (rank < 0) throw Error(fmt::format("{}: {} has an unreadable dataspace", path, name));
  Dims dims(static_cast<std::size_t>(rank));
  H5Sget_simple_extent_dims(space.id(), dims.data(), nullptr);
  return dims;
}

void check_shape(hid_t file, const std::string& path, const std::string& name,
                 const Dims& expected, const std::string& meaning) {
  const Dims dims = dataset_shape(file, path, name);
  if (dims != expected)
    throw Error(fmt::format("{}: {} has shape {} (must be {}: {})", path, name, shape_text(dims),
                            shape_text(expected), meaning));
}

H5T_class_t dataset_class(hid_t file, const std::string& path, const std::string& name,
                          H5T_sign_t* sign) {
  Handle set = checked(H5Dopen2(file, name.c_str(), H5P_DEFAULT), H5Dclose, "missing " + name,
                       path);
  Handle type = checked(H5Dget_type(set.id()), H5Tclose, "type of " + name, path);
  const H5T_class_t c = H5Tget_class(type.id());
  if (sign) *sign = c == H5T_INTEGER ? H5Tget_sign(type.id()) : H5T_SGN_NONE;
  return c;
}

void write_attr(hid_t file, const std::string& path, const std::string& obj,
                const std::string& name, hid_t type, hid_t space, const void* buf) {
  Handle o = open_object(file, obj, path);
  if (H5Aexists(o.id(), name.c_str()) > 0) H5Adelete(o.id(), name.c_str());
  Handle a = checked(H5Acreate2(o.id(), name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT),
                     H5Aclose, "cannot create attribute " + obj + "@" + name, path);
  errno = 0;
  check_write(H5Awrite(a.id(), type, buf), file, "cannot write attribute " + obj + "@" + name, path);
}

}  // namespace

Handle& Handle::operator=(Handle&& o) noexcept {
  if (this != &o) {
    if (id_ >= 0 && closer_) closer_(id_);
    id_ = o.id_;
    closer_ = o.closer_;
    o.id_ = -1;
  }
  return *this;
}

Handle::~Handle() {
  if (id_ >= 0 && closer_) closer_(id_);
}

namespace {

// prepare_hdf5's thread, joined once: by the first quiet_hdf5_errors, or at
// exit (a static destroyed before the HDF5 C++ library's exit-time H5close,
// which was registered before main).
struct Hdf5Start {
  std::thread thread;
  std::once_flag joined;
  void wait() {
    std::call_once(joined, [this] {
      if (thread.joinable()) thread.join();
    });
  }
  ~Hdf5Start() { wait(); }
};

Hdf5Start& hdf5_start() {
  static Hdf5Start start;
  return start;
}

}  // namespace

void prepare_hdf5() {
  // Before any other HDF5 call: no C library cleanup at exit; every file
  // fiberlab writes is closed explicitly, on success or failure (see
  // drop_contents). (The HDF5 C++ library still calls H5close at exit.)
  hdf5_start().thread = std::thread([] {
    H5dont_atexit();
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  });
}

void quiet_hdf5_errors() {
  hdf5_start().wait();
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

namespace {
bool abandoned_files = false;
}  // namespace

bool abandoned_a_written_file() { return abandoned_files; }

namespace {

// Closes a file being written that was not close()d: an error ended the
// write (e.g. a full disk). Its contents are dropped first (drop_contents) so
// that the close has room for the little metadata HDF5 still flushes.
herr_t abandon_written_file(hid_t id) {
  drop_contents(id);
  abandoned_files = true;
  return H5Fclose(id);
}

}  // namespace

File File::create(const std::string& path) { return create(path, path); }

File File::create(const std::string& path, const std::string& shown_as) {
  quiet_hdf5_errors();
  // H5F_CLOSE_STRONG: closing the file also closes any dataset or group whose
  // own close failed, so nothing of it is left open.
  Handle fapl = checked(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "property list", path);
  H5Pset_fclose_degree(fapl.id(), H5F_CLOSE_STRONG);
  // HDF5 1.10's format: its metadata carries checksums (common/h5_integrity.h);
  // h5py on HDF5 1.10 or later reads it.
  H5Pset_libver_bounds(fapl.id(), H5F_LIBVER_LATEST, H5F_LIBVER_LATEST);
  errno = 0;
  hid_t id = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.id());
  if (id < 0) {
    if (errno == ENOSPC || errno == EDQUOT || errno == EIO)
      throw Error(fmt::format("{}: cannot create file: {}", shown_as, std::strerror(errno)));
    throw Error(fmt::format("{}: cannot create file (is the folder writable?)", shown_as));
  }
  return File(Handle(id, abandon_written_file), shown_as);
}

void File::start_writeback() const {
  void* vfd = nullptr;
  // The default (sec2) driver's handle is a pointer to its file descriptor.
  if (H5Fget_vfd_handle(handle_.id(), H5P_DEFAULT, &vfd) < 0 || !vfd) return;
  sync_file_range(*static_cast<int*>(vfd), 0, 0, SYNC_FILE_RANGE_WRITE);
}

File File::open_read(const std::string& path) {
  quiet_hdf5_errors();
  // The whole file is read once in a child process first: damage that
  // crashes HDF5 kills the child, not this process (common/h5_integrity.h).
  probe_file(path);
  hid_t id = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (id < 0) throw Error(fmt::format("{}: cannot open as an HDF5 file", path));
  return File(Handle(id, H5Fclose), path);
}

void File::close() {
  if (handle_.id() < 0) return;
  // A file written here gets its attribute digest (common/h5_integrity.h).
  unsigned intent = 0;
  if (H5Fget_intent(handle_.id(), &intent) >= 0 && (intent & H5F_ACC_RDWR))
    set_attr("/", kDigestAttribute, attribute_digest(handle_.id(), path_));
  errno = 0;
  check(H5Fflush(handle_.id(), H5F_SCOPE_GLOBAL), "cannot write the file", path_);
  const hid_t id = handle_.id();
  handle_.release();
  check(H5Fclose(id), "cannot close the file", path_);
}

void File::create_group(const std::string& name) {
  checked(H5Gcreate2(handle_.id(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
          H5Gclose, "cannot create group " + name, path_);
}

bool File::exists(const std::string& name) const {
  // Check each path component, as H5Lexists requires.
  std::size_t pos = 1;
  while (true) {
    std::size_t next = name.find('/', pos);
    std::string prefix = name.substr(0, next);
    if (H5Lexists(handle_.id(), prefix.c_str(), H5P_DEFAULT) <= 0) return false;
    if (next == std::string::npos) return true;
    pos = next + 1;
  }
}

void File::write(const std::string& name, const Dims& dims, const std::vector<double>& data) {
  write_dataset(handle_.id(), path_, name, dims, data, H5T_NATIVE_DOUBLE, H5T_IEEE_F64LE);
}

void File::write(const std::string& name, const Dims& dims,
                 const std::vector<std::uint64_t>& data) {
  write_dataset(handle_.id(), path_, name, dims, data, H5T_NATIVE_UINT64, H5T_STD_U64LE);
}

void File::write_finite(const std::string& name, const Dims& dims, const std::vector<double>& data) {
  for (std::size_t i = 0; i < data.size(); ++i)
    if (!std::isfinite(data[i]))
      throw Error(fmt::format("{}: {} would hold {} at flat index {} (values must be finite; "
                              "nothing written)", path_, name, data[i], i));
  write(name, dims, data);
}

std::vector<double> File::read_doubles(const std::string& name, Dims* dims) const {
  return read_dataset<double>(handle_.id(), path_, name, dims, H5T_NATIVE_DOUBLE);
}

std::vector<std::uint64_t> File::read_uint64s(const std::string& name, Dims* dims) const {
  return read_dataset<std::uint64_t>(handle_.id(), path_, name, dims, H5T_NATIVE_UINT64);
}

Dims File::shape(const std::string& name) const { return dataset_shape(handle_.id(), path_, name); }

std::vector<double> File::read_doubles(const std::string& name, const Dims& expected,
                                       const std::string& meaning) const {
  check_shape(handle_.id(), path_, name, expected, meaning);
  const H5T_class_t c = dataset_class(handle_.id(), path_, name, nullptr);
  if (c != H5T_FLOAT && c != H5T_INTEGER)
    throw Error(fmt::format("{}: {} does not hold numbers (must be float64)", path_, name));
  return read_doubles(name);
}

std::vector<std::uint64_t> File::read_uint64s(const std::string& name, const Dims& expected,
                                              const std::string& meaning) const {
  check_shape(handle_.id(), path_, name, expected, meaning);
  H5T_sign_t sign = H5T_SGN_NONE;
  if (dataset_class(handle_.id(), path_, name, &sign) != H5T_INTEGER)
    throw Error(fmt::format("{}: {} does not hold integers (must be uint64)", path_, name));
  if (sign != H5T_SGN_2) return read_uint64s(name);
  // A signed dataset (e.g. written by h5py from int64): read it as such and
  // refuse negative counts rather than let HDF5 clip them.
  const std::vector<std::int64_t> v =
      read_dataset<std::int64_t>(handle_.id(), path_, name, nullptr, H5T_NATIVE_INT64);
  std::vector<std::uint64_t> out(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (v[i] < 0)
      throw Error(fmt::format("{}: {} holds the negative count {} at flat index {} (must be >= 0)",
                              path_, name, v[i], i));
    out[i] = static_cast<std::uint64_t>(v[i]);
  }
  return out;
}

void File::set_attr(const std::string& obj, const std::string& name, std::uint64_t value) {
  Handle space = checked(H5Screate(H5S_SCALAR), H5Sclose, "scalar space", path_);
  write_attr(handle_.id(), path_, obj, name, H5T_STD_U64LE, space.id(), &value);
}

void File::set_attr(const std::string& obj, const std::string& name,
                    const std::vector<std::uint64_t>& value) {
  hsize_t n = value.size();
  Handle space = checked(H5Screate_simple(1, &n, nullptr), H5Sclose, "array space", path_);
  write_attr(handle_.id(), path_, obj, name, H5T_STD_U64LE, space.id(), value.data());
}

std::uint64_t File::attr_size(const std::string& obj, const std::string& name) const {
  Handle a = open_attr(handle_.id(), obj, name, path_);
  Handle space = checked(H5Aget_space(a.id()), H5Sclose, "space", path_);
  const hssize_t n = H5Sget_simple_extent_npoints(space.id());
  if (n < 0) throw Error(fmt::format("{}: attribute {}@{} has an unreadable dataspace", path_, obj, name));
  return static_cast<std::uint64_t>(n);
}

std::uint64_t File::attr_uint64(const std::string& obj, const std::string& name) const {
  const std::string what = obj + "@" + name;
  if (attr_size(obj, name) != 1)
    throw Error(fmt::format("{}: attribute {} is not a single value (must be one uint64)", path_, what));
  Handle a = open_attr(handle_.id(), obj, name, path_);
  Handle type = checked(H5Aget_type(a.id()), H5Tclose, "attribute type", path_);
  if (H5Tget_class(type.id()) != H5T_INTEGER)
    throw Error(fmt::format("{}: attribute {} is not an integer (must be uint64)", path_, what));
  if (H5Tget_sign(type.id()) == H5T_SGN_2) {
    std::int64_t v = 0;
    check(H5Aread(a.id(), H5T_NATIVE_INT64, &v), "cannot read " + what, path_);
    return static_cast<std::uint64_t>(v);  // the bits of fiberlab 0.1's int64 seed
  }
  std::uint64_t v = 0;
  check(H5Aread(a.id(), H5T_NATIVE_UINT64, &v), "cannot read " + what, path_);
  return v;
}

std::vector<std::uint64_t> File::attr_uint64s(const std::string& obj, const std::string& name,
                                              std::size_t max_count) const {
  const std::string what = obj + "@" + name;
  const std::uint64_t n = attr_size(obj, name);
  if (n < 1 || n > max_count)
    throw Error(fmt::format("{}: attribute {} holds {} values (must hold 1 to {})", path_, what, n,
                            max_count));
  Handle a = open_attr(handle_.id(), obj, name, path_);
  Handle type = checked(H5Aget_type(a.id()), H5Tclose, "attribute type", path_);
  const H5T_class_t c = H5Tget_class(type.id());
  std::vector<std::uint64_t> out(n);
  if (c == H5T_INTEGER && H5Tget_sign(type.id()) != H5T_SGN_2) {
    check(H5Aread(a.id(), H5T_NATIVE_UINT64, out.data()), "cannot read " + what, path_);
    return out;
  }
  if (c != H5T_FLOAT && c != H5T_INTEGER)
    throw Error(fmt::format("{}: attribute {} does not hold integers (must be uint64)", path_, what));
  std::vector<double> v(n);
  check(H5Aread(a.id(), H5T_NATIVE_DOUBLE, v.data()), "cannot read " + what, path_);
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!(v[i] >= 0.0 && v[i] < 18446744073709551616.0 && v[i] == std::floor(v[i])))
      throw Error(fmt::format("{}: attribute {} holds {} (must hold integers in [0, 2^64 - 1])",
                              path_, what, v[i]));
    out[i] = static_cast<std::uint64_t>(v[i]);
  }
  return out;
}

void File::create_dataset(const std::string& name, const Dims& dims, Type type) {
  Handle space = checked(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr),
                         H5Sclose, "dataspace for " + name, path_);
  Handle dcpl = dataset_creation(dims, true, path_);
  const hid_t file_type = type == Type::Float64 ? H5T_IEEE_F64LE
                          : type == Type::Int64 ? H5T_STD_I64LE
                                                : H5T_STD_U64LE;
  checked(H5Dcreate2(handle_.id(), name.c_str(), file_type, space.id(), H5P_DEFAULT, dcpl.id(),
                     H5P_DEFAULT),
          H5Dclose, "cannot create " + name, path_);
}

void File::write_slab(const std::string& name, hsize_t i, const std::vector<double>& data) {
  slab_io<double>(handle_.id(), path_, name, {i}, nullptr, &data, H5T_NATIVE_DOUBLE);
}

namespace {

// The type a dataset's file type is read and written as.
File::Type stored_type(hid_t type) {
  return H5Tget_class(type) == H5T_FLOAT     ? File::Type::Float64
         : H5Tget_sign(type) == H5T_SGN_2 ? File::Type::Int64
                                           : File::Type::UInt64;
}

// A plan from a dataset's type, dims and creation list. Direct: chunk dims
// (1, 1, rows_per_chunk, whole trailing dims), deflate the only filter.
File::RowPlan plan_from_layout(const std::string& name, File::Type type, const Dims& dims,
                               hid_t dcpl) {
  File::RowPlan plan;
  plan.name = name;
  plan.type = type;
  if constexpr (std::endian::native != std::endian::little) return plan;  // file types are LE
  const int level = only_deflate_level(dcpl);
  const std::size_t rank = dims.size();
  if (level < 0 || rank < 3) return plan;
  const Dims chunk = chunk_dims(dcpl, rank);
  if (chunk.empty() || chunk[0] != 1 || chunk[1] != 1) return plan;
  std::size_t cells = 1;
  for (std::size_t d = 3; d < rank; ++d) {
    if (chunk[d] != dims[d]) return plan;
    cells *= dims[d];
  }
  plan.rows = dims[2];
  plan.rows_per_chunk = chunk[2];
  plan.row_bytes = cells * sizeof(double);  // float64 and (u)int64 alike
  plan.level = level;
  plan.direct = true;
  return plan;
}

}  // namespace

File::RowPlan File::plan_rows(const std::string& name) {
  Handle set = checked(H5Dopen2(handle_.id(), name.c_str(), H5P_DEFAULT), H5Dclose, "missing " + name, path_);
  Handle type = checked(H5Dget_type(set.id()), H5Tclose, "type of " + name, path_);
  Handle dcpl = checked(H5Dget_create_plist(set.id()), H5Pclose, "creation list of " + name, path_);
  Handle space = checked(H5Dget_space(set.id()), H5Sclose, "dataspace of " + name, path_);
  Dims dims(std::max(0, H5Sget_simple_extent_ndims(space.id())));
  H5Sget_simple_extent_dims(space.id(), dims.data(), nullptr);
  RowPlan plan = plan_from_layout(name, stored_type(type.id()), dims, dcpl.id());
  plan.set = std::move(set);
  return plan;
}

File::RowPlan File::plan_new_rows(const std::string& name, const Dims& dims, Type type) {
  Handle dcpl = dataset_creation(dims, true, name);
  return plan_from_layout(name, type, dims, dcpl.id());
}

void File::attach(RowPlan& plan) {
  if (plan.set.id() >= 0) return;
  RowPlan opened = plan_rows(plan.name);
  if (opened.type != plan.type || opened.direct != plan.direct || opened.rows != plan.rows ||
      opened.rows_per_chunk != plan.rows_per_chunk || opened.row_bytes != plan.row_bytes ||
      opened.level != plan.level)
    throw Error(fmt::format("{}: internal error: {} was not created as planned", path_, plan.name));
  plan.set = std::move(opened.set);
}

namespace {

bool all_zero(const unsigned char* p, std::size_t n) {
  return n == 0 || (p[0] == 0 && std::memcmp(p, p + 1, n - 1) == 0);
}

// Each chunk of a row deflated alone; an edge chunk (past the dataset's end)
// padded with zeros to the whole chunk, as HDF5 stores it. A chunk of zeros
// only is left empty: it is not stored, and HDF5 reads a chunk never written
// as the datasets' fill value, 0 (sparse results: few photons, many lobes).
void deflate_chunks(const File::RowPlan& plan, const unsigned char* data, std::size_t bytes,
                    Deflater& z, File::PreparedRow& out) {
  if (bytes != plan.rows * plan.row_bytes)
    throw Error(fmt::format("internal error: a row of {} has {} bytes, not {}", plan.name, bytes,
                            plan.rows * plan.row_bytes));
  if (z.level() != plan.level)
    throw Error(fmt::format("internal error: {} is deflated at level {}, not {}", plan.name,
                            plan.level, z.level()));
  const std::size_t chunks = (plan.rows + plan.rows_per_chunk - 1) / plan.rows_per_chunk;
  out.chunks.resize(chunks);
  const std::size_t chunk_bytes = plan.rows_per_chunk * plan.row_bytes;
  for (std::size_t c = 0; c < chunks; ++c) {
    const std::size_t first = c * chunk_bytes, valid = std::min(chunk_bytes, bytes - first);
    if (all_zero(data + first, valid)) out.chunks[c].clear();
    else z.deflate(data + first, valid, chunk_bytes, out.chunks[c]);
  }
}

template <typename T>
void prepare(const File::RowPlan& plan, File::Type type, const std::vector<T>& values, Deflater& z,
             File::PreparedRow& out, std::vector<T>& kept) {
  if (plan.type != type)
    throw Error(fmt::format("internal error: {} is not a dataset of this type", plan.name));
  if (!plan.direct) {
    kept = values;
    return;
  }
  deflate_chunks(plan, reinterpret_cast<const unsigned char*>(values.data()),
                 values.size() * sizeof(T), z, out);
}

}  // namespace

void File::prepare_row(const RowPlan& plan, const std::vector<double>& values, Deflater& z,
                       PreparedRow& out) {
  prepare(plan, Type::Float64, values, z, out, out.doubles);
}

void File::prepare_row(const RowPlan& plan, const std::vector<std::uint64_t>& values,
                       Deflater& z, PreparedRow& out) {
  prepare(plan, Type::UInt64, values, z, out, out.words);
}

void File::prepare_row(const RowPlan& plan, const std::vector<std::int64_t>& values, Deflater& z,
                       PreparedRow& out) {
  prepare(plan, Type::Int64, values, z, out, out.signed_words);
}

void File::write_row(const RowPlan& plan, hsize_t i, hsize_t j, const PreparedRow& row) {
  if (!plan.direct) {
    if (plan.type == Type::Float64) write_slab_row(plan.name, i, j, row.doubles);
    else if (plan.type == Type::Int64) write_slab_row(plan.name, i, j, row.signed_words);
    else write_slab_row(plan.name, i, j, row.words);
    return;
  }
  Handle space = checked(H5Dget_space(plan.set.id()), H5Sclose, "dataspace of " + plan.name, path_);
  Dims offset(H5Sget_simple_extent_ndims(space.id()), 0);
  offset[0] = i;
  offset[1] = j;
  for (std::size_t c = 0; c < row.chunks.size(); ++c) {
    if (row.chunks[c].empty()) continue;  // zeros only: not stored (deflate_chunks)
    offset[2] = c * plan.rows_per_chunk;
    errno = 0;
    check_write(H5Dwrite_chunk(plan.set.id(), H5P_DEFAULT, 0, offset.data(), row.chunks[c].size(),
                               row.chunks[c].data()),
                handle_.id(), "cannot write " + plan.name, path_);
  }
}

void File::write_rows(const RowPlan& plan, hsize_t i, const PreparedRow& all) {
  if (plan.direct) throw Error("internal error: write_rows of a direct plan (" + plan.name + ")");
  if (plan.type == Type::Float64)
    slab_io<double>(handle_.id(), path_, plan.name, {i}, nullptr, &all.doubles, H5T_NATIVE_DOUBLE);
  else if (plan.type == Type::Int64)
    slab_io<std::int64_t>(handle_.id(), path_, plan.name, {i}, nullptr, &all.signed_words, H5T_NATIVE_INT64);
  else
    slab_io<std::uint64_t>(handle_.id(), path_, plan.name, {i}, nullptr, &all.words, H5T_NATIVE_UINT64);
}

void File::end_rows(const RowPlan& plan) {
  if (!plan.direct) return;  // write_slab_row flushed
  errno = 0;
  check_write(H5Dflush(plan.set.id()), handle_.id(), "cannot write " + plan.name, path_);
}

void File::write_slab_row(const std::string& name, hsize_t i, hsize_t j, const std::vector<double>& data) {
  slab_io<double>(handle_.id(), path_, name, {i, j}, nullptr, &data, H5T_NATIVE_DOUBLE);
}

void File::write_slab_row(const std::string& name, hsize_t i, hsize_t j,
                          const std::vector<std::uint64_t>& data) {
  slab_io<std::uint64_t>(handle_.id(), path_, name, {i, j}, nullptr, &data, H5T_NATIVE_UINT64);
}

void File::write_slab_row(const std::string& name, hsize_t i, hsize_t j,
                          const std::vector<std::int64_t>& data) {
  slab_io<std::int64_t>(handle_.id(), path_, name, {i, j}, nullptr, &data, H5T_NATIVE_INT64);
}

void File::write_slab(const std::string& name, hsize_t i, const std::vector<std::uint64_t>& data) {
  slab_io<std::uint64_t>(handle_.id(), path_, name, {i}, nullptr, &data, H5T_NATIVE_UINT64);
}

std::vector<double> File::read_slab_doubles(const std::string& name, hsize_t i) const {
  std::vector<double> v;
  slab_io<double>(handle_.id(), path_, name, {i}, &v, nullptr, H5T_NATIVE_DOUBLE);
  return v;
}

std::vector<std::uint64_t> File::read_slab_uint64s(const std::string& name, hsize_t i) const {
  std::vector<std::uint64_t> v;
  slab_io<std::uint64_t>(handle_.id(), path_, name, {i}, &v, nullptr, H5T_NATIVE_UINT64);
  return v;
}

std::vector<std::int64_t> File::read_slab_int64s(const std::string& name, hsize_t i) const {
  std::vector<std::int64_t> v;
  slab_io<std::int64_t>(handle_.id(), path_, name, {i}, &v, nullptr, H5T_NATIVE_INT64);
  return v;
}

Dims File::dims(const std::string& name) const {
  Handle set = checked(H5Dopen2(handle_.id(), name.c_str(), H5P_DEFAULT), H5Dclose,
                       "missing " + name, path_);
  Handle space = checked(H5Dget_space(set.id()), H5Sclose, "dataspace of " + name, path_);
  const int rank = H5Sget_simple_extent_ndims(space.id());
  if (rank < 0) throw Error(fmt::format("{}: HDF5 error: dataspace of {}", path_, name));
  Dims d(rank);
  H5Sget_simple_extent_dims(space.id(), d.data(), nullptr);
  return d;
}

void File::set_attr(const std::string& obj, const std::string& name, const std::string& value) {
  // Variable-length UTF-8 string: h5py reads it as a Python str.
  Handle type = checked(H5Tcopy(H5T_C_S1), H5Tclose, "string type", path_);
  H5Tset_size(type.id(), H5T_VARIABLE);
  H5Tset_cset(type.id(), H5T_CSET_UTF8);
  Handle space = checked(H5Screate(H5S_SCALAR), H5Sclose, "scalar space", path_);
  const char* p = value.c_str();
  write_attr(handle_.id(), path_, obj, name, type.id(), space.id(), &p);
}

void File::set_attr(const std::string& obj, const std::string& name, double value) {
  Handle space = checked(H5Screate(H5S_SCALAR), H5Sclose, "scalar space", path_);
  write_attr(handle_.id(), path_, obj, name, H5T_NATIVE_DOUBLE, space.id(), &value);
}

void File::set_attr(const std::string& obj, const std::string& name, std::int64_t value) {
  Handle space = checked(H5Screate(H5S_SCALAR), H5Sclose, "scalar space", path_);
  write_attr(handle_.id(), path_, obj, name, H5T_NATIVE_INT64, space.id(), &value);
}

void File::set_attr(const std::string& obj, const std::string& name,
                    const std::vector<double>& value) {
  hsize_t n = value.size();
  Handle space = checked(H5Screate_simple(1, &n, nullptr), H5Sclose, "array space", path_);
  write_attr(handle_.id(), path_, obj, name, H5T_NATIVE_DOUBLE, space.id(), value.data());
}

bool File::has_attr(const std::string& obj, const std::string& name) const {
  return H5Aexists_by_name(handle_.id(), obj.c_str(), name.c_str(), H5P_DEFAULT) > 0;
}

std::string File::attr_string(const std::string& obj, const std::string& name) const {
  Handle a = open_attr(handle_.id(), obj, name, path_);
  Handle ftype = checked(H5Aget_type(a.id()), H5Tclose, "attribute type", path_);
  if (H5Tget_class(ftype.id()) != H5T_STRING)
    throw Error(fmt::format("{}: attribute {}@{} is not a string", path_, obj, name));
  if (attr_size(obj, name) != 1)
    throw Error(fmt::format("{}: attribute {}@{} is not a single string", path_, obj, name));
  if (H5Tis_variable_str(ftype.id()) > 0) {
    Handle mtype = checked(H5Tcopy(H5T_C_S1), H5Tclose, "string type", path_);
    H5Tset_size(mtype.id(), H5T_VARIABLE);
    H5Tset_cset(mtype.id(), H5Tget_cset(ftype.id()));
    char* p = nullptr;
    check(H5Aread(a.id(), mtype.id(), &p), "cannot read " + name, path_);
    std::string s = p ? p : "";
    Handle space = checked(H5Aget_space(a.id()), H5Sclose, "space", path_);
    H5Dvlen_reclaim(mtype.id(), space.id(), H5P_DEFAULT, &p);
    return s;
  }
  const std::size_t n = H5Tget_size(ftype.id());
  if (n > kMaxStringBytes)
    throw Error(fmt::format("{}: attribute {}@{} is a string longer than {} bytes", path_, obj,
                            name, kMaxStringBytes));
  std::string s(n, '\0');
  check(H5Aread(a.id(), ftype.id(), s.data()), "cannot read " + name, path_);
  s.resize(s.find('\0') == std::string::npos ? n : s.find('\0'));
  return s;
}

double File::attr_double(const std::string& obj, const std::string& name) const {
  if (attr_size(obj, name) != 1)
    throw Error(fmt::format("{}: attribute {}@{} is not a single number", path_, obj, name));
  Handle a = open_attr(handle_.id(), obj, name, path_);
  double v = 0;
  check(H5Aread(a.id(), H5T_NATIVE_DOUBLE, &v), "cannot read " + name, path_);
  return v;
}

std::int64_t File::attr_int(const std::string& obj, const std::string& name) const {
  if (attr_size(obj, name) != 1)
    throw Error(fmt::format("{}: attribute {}@{} is not a single number", path_, obj, name));
  Handle a = open_attr(handle_.id(), obj, name, path_);
  std::int64_t v = 0;
  check(H5Aread(a.id(), H5T_NATIVE_INT64, &v), "cannot read " + name, path_);
  return v;
}

std::vector<double> File::attr_doubles(const std::string& obj, const std::string& name) const {
  Handle a = open_attr(handle_.id(), obj, name, path_);
  Handle space = checked(H5Aget_space(a.id()), H5Sclose, "space", path_);
  const hssize_t n = H5Sget_simple_extent_npoints(space.id());
  if (n < 0 || n > (hssize_t{1} << 24))
    throw Error(fmt::format("{}: attribute {}@{} declares {} values (at most 2^24 are read)", path_,
                            obj, name, n));
  std::vector<double> v(static_cast<std::size_t>(n));
  check(H5Aread(a.id(), H5T_NATIVE_DOUBLE, v.data()), "cannot read " + name, path_);
  return v;
}

}  // namespace fiberlab::h5
