#pragma once
// A report folder (`--report DIR`) written whole or not at all, and never
// through a link planted in it: every file of the report (metrics, report.md,
// report_data.h5, atlas_tables.md, the plotting script's PNGs, SVGs,
// report.html and plot_log.txt) is first written into a private staging
// folder DIR/.report-staging-PID.XXXXXX (mode 0700, made by mkdtemp, so
// nobody else can plant anything in it), and commit() moves them into DIR by
// rename(), which replaces a name without following it. Before any is moved,
// every name is checked in DIR: one that exists as anything but a regular
// file (a symbolic link, a folder, a FIFO) refuses the whole report, naming
// it, and nothing is moved. A failure before commit() (a full disk, an
// exception) removes the staging folder, and DIR too if this made it.
// Staging folders of processes that no longer exist (SIGKILL) are removed
// when the next report is made in DIR.
#include <exception>
#include <string>

namespace fiberlab::compare {

class ReportFolder {
 public:
  // Creates DIR (and missing parents) when it does not exist, and the
  // staging folder in it. Throws fiberlab::Error naming DIR.
  explicit ReportFolder(std::string dir);
  ~ReportFolder();  // without commit(): removes the staging folder (and DIR if made here)
  ReportFolder(const ReportFolder&) = delete;
  ReportFolder& operator=(const ReportFolder&) = delete;

  const std::string& dir() const { return dir_; }
  // Where the report's files are written (the commands' `dir` until commit()).
  const std::string& staging() const { return staging_; }
  // Moves every staged file into DIR (see above); a report.html of an
  // earlier report is removed when this one has none.
  void commit();
  // `e` again, with the staging folder's path in its message shown as DIR
  // (the user never sees the staging folder's name).
  [[noreturn]] void rethrow(const std::exception& e) const;

 private:
  std::string dir_, staging_, created_;  // created_: the topmost folder made here, or ""
  bool committed_ = false;
};

// Checks, without creating anything, that --report DIR can be made: DIR is
// a folder, or its nearest existing ancestor is a writable folder.
void check_report_dir_possible(const std::string& dir);

}  // namespace fiberlab::compare
