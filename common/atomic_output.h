#pragma once
// A result file is written completely or not at all (SPEC section 9): write
// to a temporary name in the same folder (.NAME.tmp-PID), flush it to disk,
// then rename it over the target.
//
// The temporary file is removed on every way out: an exception (destructor),
// SIGINT/SIGTERM during the write (a TempFileGuard, common/interrupt.h).
// The temporary file is created by the constructor (O_EXCL | O_NOFOLLOW,
// after removing whatever had its name), so that no writer follows a link
// planted at that predictable name.
// Temporary files of the same target left by processes that no longer exist
// (a crash, SIGKILL) are removed when the next AtomicOutput for that target
// is made.
#include <optional>
#include <string>
#include <vector>

#include "common/interrupt.h"

namespace fiberlab {

class AtomicOutput {
 public:
  // Checks the target before any work: a non-empty path whose folder exists
  // and is writable; if it exists, a writable regular file (not a folder, a
  // FIFO, a device, a socket or a symbolic link) that is none of `inputs`
  // (the files the command reads). Throws fiberlab::Error naming the path.
  explicit AtomicOutput(std::string target, const std::vector<std::string>& inputs = {});
  ~AtomicOutput();  // removes the temporary file unless commit() ran
  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;

  const std::string& temp_path() const { return temp_; }
  const std::string& target() const { return target_; }
  // fsync the temporary file, rename it to the target, fsync the folder.
  // The temporary file must be closed (HDF5 file closed) before.
  void commit();

 private:
  std::string target_, temp_, dir_;
  std::optional<TempFileGuard> guard_;
  bool committed_ = false;
};

// Removes the temporary files of `target` (.NAME.tmp-PID, regular files
// only, never through a symbolic link) left by processes that no longer
// exist (SIGKILL, a crash): what AtomicOutput's constructor does, for
// callers that may not write `target` again (a run resumed from a
// checkpoint may finish before its next checkpoint).
void remove_stale_temporaries(const std::string& target);

// A name that every file made from it can have: no control characters (a
// newline or tab in a name breaks the stored config and every listing), and
// its temporary name within NAME_MAX and PATH_MAX. fiberlab::Error naming
// the limit otherwise. Part of check_output_target; callers that derive
// other names (OUT.checkpoint.h5) check those too.
void check_output_name(const std::string& target);

// The same checks as AtomicOutput's constructor, without creating anything.
void check_output_target(const std::string& target, const std::vector<std::string>& inputs = {});

}  // namespace fiberlab
