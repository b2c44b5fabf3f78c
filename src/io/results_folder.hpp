#pragma once
// A results folder holds one run (docs/contract.md "Result files"): a command writes into a
// staging folder beside the target, `.<leaf>.staging-<pid>`, and commit() swaps it with the
// target in one atomic exchange (renameat2 RENAME_EXCHANGE), so that the target is always
// entirely the old run or entirely the new one, also when the run is killed. A lock file
// beside it, `.<leaf>.lock` (flock), refuses a second run into the same folder while one is
// writing. Only folders a run can own are replaced: a missing or empty folder, or one that
// holds a run.json (a results folder); anything else is refused before any work.
//
// Usage:
//   io::ResultsFolder out(user_out_path);     // checks, lock, staging; throws InputError
//   ctx.out_dir = out.staging();              // every file of the run goes there
//   ... run ...
//   out.commit();                             // exit 0 or 3: the run replaces the folder
//   (destructor without commit: staging removed, target untouched, lock released)
#include <filesystem>
#include <string>

namespace shroudsim::io {

class ResultsFolder {
 public:
  /// option: how the user named the folder in messages (e.g. "--out"). Throws InputError
  /// when the target is a file or a folder that is not a results folder, its parent cannot
  /// be created or written, the name is too long for the file system, or another run holds
  /// the lock.
  /// resume (`study --resume`): the new run starts from what an earlier one wrote: a killed
  /// run's staging folder (the newest, renamed to this run's), else a copy of the target's
  /// subfolders (the points of a finished study); resumed_from() says which.
  ResultsFolder(std::filesystem::path target, const std::string& option, bool resume = false);
  ~ResultsFolder();
  ResultsFolder(const ResultsFolder&) = delete;
  ResultsFolder& operator=(const ResultsFolder&) = delete;

  const std::filesystem::path& target() const { return target_; }
  const std::filesystem::path& staging() const { return staging_; }
  /// The staging folder becomes the target (the old target is removed). Throws
  /// std::runtime_error when the file system refuses.
  void commit();
  /// "" (a fresh start), "a killed run" or "the previous results".
  const std::string& resumed_from() const { return resumed_from_; }

 private:
  std::filesystem::path target_, staging_;
  std::string resumed_from_;
  int lock_fd_ = -1;
  bool committed_ = false;
};

}  // namespace shroudsim::io
