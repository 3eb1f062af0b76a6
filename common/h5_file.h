#pragma once
// A thin RAII layer over the HDF5 C API: just what fiberlab's result files need
// (groups, n-dimensional float64 / uint64 datasets, scalar and array attributes).
// Errors are thrown as fiberlab::Error naming the file and the object.
#include <hdf5.h>

#include <cstdint>
#include <string>
#include <vector>

#include "common/deflater.h"

namespace fiberlab::h5 {

// Owns one hid_t and closes it with the matching H5*close.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  Handle(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& o) noexcept : id_(o.id_), closer_(o.closer_) { o.id_ = -1; }
  Handle& operator=(Handle&& o) noexcept;
  ~Handle();
  hid_t id() const { return id_; }
  void release() { id_ = -1; }  // the caller closes the id

 private:
  hid_t id_ = -1;
  Closer closer_ = nullptr;
};

using Dims = std::vector<hsize_t>;

class File {
 public:
  // Truncates. A created file must be close()d: one destroyed without it
  // (an exception during the write, e.g. a full disk) is abandoned, its
  // contents dropped. Disk errors are thrown naming the file and errno.
  static File create(const std::string& path);
  // The same, with errors naming `shown_as` (the target of an AtomicOutput
  // whose temporary file `path` is) instead of `path`.
  static File create(const std::string& path, const std::string& shown_as);
  static File open_read(const std::string& path);
  const std::string& path() const { return path_; }
  void close();  // flush and close; throws naming the file (e.g. disk full)
  // Asks the kernel to start writing what was written so far to the disk,
  // without waiting (sync_file_range), so that the final fsync waits less.
  // Best effort: an error is left for the fsync to report.
  void start_writeback() const;

  void create_group(const std::string& name);
  bool exists(const std::string& name) const;  // a link at this path

  void write(const std::string& name, const Dims& dims, const std::vector<double>& data);
  void write(const std::string& name, const Dims& dims, const std::vector<std::uint64_t>& data);
  // As write(), after checking that every value is finite: a NaN or an
  // infinity (e.g. a model evaluated far outside its domain) is refused with
  // one line naming the dataset and the first bad value, and nothing is written.
  void write_finite(const std::string& name, const Dims& dims, const std::vector<double>& data);
  std::vector<double> read_doubles(const std::string& name, Dims* dims = nullptr) const;
  std::vector<std::uint64_t> read_uint64s(const std::string& name, Dims* dims = nullptr) const;

  // Files from outside are read in two steps: the declared shape first
  // (nothing allocated), then the data only when the shape is the expected
  // one. `meaning` says where the expected shape comes from, for the error
  // ("K x L x C = 1 x 4 x 3, from config_yaml").
  Dims shape(const std::string& name) const;  // a dataset's dimensions
  std::vector<double> read_doubles(const std::string& name, const Dims& expected,
                                   const std::string& meaning) const;
  // Integer datasets only (a float or a negative signed value is refused).
  std::vector<std::uint64_t> read_uint64s(const std::string& name, const Dims& expected,
                                          const std::string& meaning) const;
  // Datasets written and read one slab at a time (slab i = index i along the
  // first dimension), so that a file larger than memory can be streamed.
  enum class Type { Float64, UInt64, Int64 };
  void create_dataset(const std::string& name, const Dims& dims, Type type);
  void write_slab(const std::string& name, hsize_t i, const std::vector<double>& data);
  void write_slab(const std::string& name, hsize_t i, const std::vector<std::uint64_t>& data);
  // Row j (index j along the second dimension) of slab i: a part of a slab,
  // so that a slab need not be in memory at once.
  void write_slab_row(const std::string& name, hsize_t i, hsize_t j, const std::vector<double>& data);
  void write_slab_row(const std::string& name, hsize_t i, hsize_t j,
                      const std::vector<std::uint64_t>& data);
  void write_slab_row(const std::string& name, hsize_t i, hsize_t j,
                      const std::vector<std::int64_t>& data);
  // Rows stored as chunks deflated ahead of HDF5 (H5Dwrite_chunk), so that
  // the deflating, which needs no HDF5 call, can run on threads:
  //   RowPlan plan = f.plan_rows(name);                 // serial: HDF5's layout
  //   File::prepare_row(plan, values, deflater, row);   // any thread, own Deflater
  //   f.write_row(plan, i, j, row); ... f.end_rows(plan);  // serial
  // The chunks are zlib-format streams at the dataset's deflate level, which
  // HDF5's deflate filter reads like its own. A dataset whose chunks are not
  // whole rows deflated alone (or a big-endian machine) keeps the row's
  // values as they are, written through write_slab_row.
  struct RowPlan {
    std::string name;
    Handle set;
    Type type = Type::Float64;
    bool direct = false;                   // the fields below are set when true
    hsize_t rows = 0, rows_per_chunk = 0;  // along the third dimension
    std::size_t row_bytes = 0;             // one index of the third dimension
    int level = 0;                         // deflate's
  };
  struct PreparedRow {
    std::vector<std::vector<unsigned char>> chunks;  // direct: one stream per chunk
    std::vector<double> doubles;                     // otherwise: the values
    std::vector<std::uint64_t> words;
    std::vector<std::int64_t> signed_words;
  };
  RowPlan plan_rows(const std::string& name);
  // The plan of a dataset create_dataset(name, dims, type) will make, before
  // any file exists (so that rows can be prepared while the file is created),
  // and its dataset opened into it once created (checked against the plan).
  static RowPlan plan_new_rows(const std::string& name, const Dims& dims, Type type);
  void attach(RowPlan& plan);
  // Throws fiberlab::Error if the values do not fill a row of the plan's
  // type, or if z's level is not the dataset's.
  static void prepare_row(const RowPlan& plan, const std::vector<double>& values, Deflater& z,
                          PreparedRow& out);
  static void prepare_row(const RowPlan& plan, const std::vector<std::uint64_t>& values,
                          Deflater& z, PreparedRow& out);
  static void prepare_row(const RowPlan& plan, const std::vector<std::int64_t>& values,
                          Deflater& z, PreparedRow& out);
  void write_row(const RowPlan& plan, hsize_t i, hsize_t j, const PreparedRow& row);
  // Slab i of a plan that is not direct, every row at once (`all`'s vector
  // of the plan's type, rows one after the other), in one write and one
  // flush: row by row, each flush deflated again the whole chunk the row
  // shares with its neighbours (up to 65536 cells), so writing L small rows
  // took time quadratic in L.
  void write_rows(const RowPlan& plan, hsize_t i, const PreparedRow& all);
  // After a plan's last row: flushes, so that a failed write is reported here.
  void end_rows(const RowPlan& plan);
  std::vector<double> read_slab_doubles(const std::string& name, hsize_t i) const;
  std::vector<std::uint64_t> read_slab_uint64s(const std::string& name, hsize_t i) const;
  std::vector<std::int64_t> read_slab_int64s(const std::string& name, hsize_t i) const;
  Dims dims(const std::string& name) const;  // of a dataset

  // Attributes on an object ("/" for the root).
  void set_attr(const std::string& obj, const std::string& name, const std::string& value);
  void set_attr(const std::string& obj, const std::string& name, double value);
  void set_attr(const std::string& obj, const std::string& name, std::int64_t value);
  void set_attr(const std::string& obj, const std::string& name, std::uint64_t value);
  void set_attr(const std::string& obj, const std::string& name,
                const std::vector<std::uint64_t>& value);
  void set_attr(const std::string& obj, const std::string& name, const std::vector<double>& value);
  bool has_attr(const std::string& obj, const std::string& name) const;
  std::string attr_string(const std::string& obj, const std::string& name) const;
  double attr_double(const std::string& obj, const std::string& name) const;
  std::int64_t attr_int(const std::string& obj, const std::string& name) const;
  std::vector<double> attr_doubles(const std::string& obj, const std::string& name) const;
  // An exact unsigned 64-bit integer. Integer attributes only; a signed one
  // is read as the two's-complement bits of an int64 (fiberlab 0.1 stored
  // uint64 seeds as int64, so -1 means 2^64 - 1).
  std::uint64_t attr_uint64(const std::string& obj, const std::string& name) const;
  // An array of unsigned 64-bit integers (at most max_count). Unsigned
  // integers exactly; float64 (fiberlab 0.1's merged_seeds) when every value
  // is a finite integer in [0, 2^64).
  std::vector<std::uint64_t> attr_uint64s(const std::string& obj, const std::string& name,
                                          std::size_t max_count) const;
  // The number of values an attribute holds (1 for a scalar).
  std::uint64_t attr_size(const std::string& obj, const std::string& name) const;

 private:
  File(Handle h, std::string path) : handle_(std::move(h)), path_(std::move(path)) {}
  Handle handle_;
  std::string path_;
};

// Called first in main(): turns the HDF5 C library's atexit cleanup off
// (fiberlab closes every file it writes explicitly; a write that failed drops
// the file's contents first so that its ids close, see drop_contents in the
// .cpp) and silences HDF5's error printing. On a thread of its own: this is
// the library's initialisation, about 2 ms, which then overlaps the parsing
// of the command line and the config (nothing else calls HDF5 before
// quiet_hdf5_errors, which waits for it: every File starts there).
void prepare_hdf5();

// Silences HDF5's automatic error stack printing; fiberlab reports its own.
// Waits for prepare_hdf5's thread first.
void quiet_hdf5_errors();

// True once a file being written was abandoned after a failed write (e.g. a
// full disk). HDF5 1.10 may then keep a file id it can no longer close, and
// the HDF5 C++ library's exit-time H5close crashes on it (found by the
// sanitizer job, Hostile.DiskFullLeavesNothingAndDoesNotCrash), so the
// program ends without the library's exit-time cleanup (cli/main.cpp).
// A workaround, not a root-cause fix.
bool abandoned_a_written_file();

}  // namespace fiberlab::h5
