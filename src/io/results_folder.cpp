#include "io/results_folder.hpp"

#include <fcntl.h>
#include <stdio.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <system_error>
#include <vector>

#include "core/error.hpp"

namespace shroudsim::io {

namespace fs = std::filesystem;

namespace {

// Leaf names up to this length leave room for ".<leaf>.staging-<pid>" within NAME_MAX (255).
constexpr std::size_t kMaxLeaf = 200;

bool is_results_folder(const fs::path& p) {
  std::error_code ec;
  if (fs::exists(p / "run.json", ec)) return true;
  return fs::is_empty(p, ec) && !ec;
}

}  // namespace

ResultsFolder::ResultsFolder(fs::path target, const std::string& option, bool resume) {
  std::error_code ec;
  target = fs::absolute(target, ec).lexically_normal();
  if (!target.has_filename()) target = target.parent_path();  // "dir/" -> "dir"
  target_ = target;
  const std::string where = option + " " + target_.string();
  const std::string leaf = target_.filename().string();
  if (leaf.empty() || leaf == "." || leaf == "..") throw InputError(where + ": not a folder name a run can write");
  if (leaf.size() > kMaxLeaf)
    throw InputError(where + ": the folder name has " + std::to_string(leaf.size()) + " characters (at most " +
                     std::to_string(kMaxLeaf) + "; a case's name is the default folder name)");
  if (fs::exists(target_, ec) && !fs::is_directory(target_, ec))
    throw InputError(where + ": exists and is not a folder");
  if (fs::is_directory(target_, ec) && !is_results_folder(target_))
    throw InputError(where +
                     ": exists and is not a results folder (no run.json, not empty); a run replaces its "
                     "whole folder: choose another folder");
  const fs::path parent = target_.parent_path();
  fs::create_directories(parent, ec);
  if (ec || !fs::is_directory(parent) || ::access(parent.c_str(), W_OK | X_OK) != 0)
    throw InputError(where + ": its parent folder " + parent.string() + " cannot be created or written" +
                     (ec ? " (" + ec.message() + ")" : ""));

  const fs::path lock = parent / ("." + leaf + ".lock");
  lock_fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (lock_fd_ < 0)
    throw InputError(where + ": cannot create the lock file " + lock.string() + ": " + std::strerror(errno));
  if (::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
    ::close(lock_fd_);
    lock_fd_ = -1;
    throw InputError(where +
                     ": another shroudsim run is writing this results folder; wait for it to finish or "
                     "choose another folder");
  }
  // Holding the lock, any staging folder of this target is a killed run's: removed, or with
  // resume the newest is kept as this run's staging folder.
  staging_ = parent / ("." + leaf + ".staging-" + std::to_string(::getpid()));
  fs::path newest;
  fs::file_time_type newest_time{};
  std::vector<fs::path> killed;
  for (const auto& e : fs::directory_iterator(parent, ec)) {
    const std::string n = e.path().filename().string();
    if (n.rfind("." + leaf + ".staging-", 0) != 0) continue;
    killed.push_back(e.path());
    const auto t = fs::last_write_time(e.path(), ec);
    if (resume && (newest.empty() || t > newest_time)) newest = e.path(), newest_time = t;
  }
  for (const auto& k : killed)
    if (k != newest) fs::remove_all(k, ec);
  if (!newest.empty()) {
    fs::rename(newest, staging_, ec);
    if (!ec) resumed_from_ = "a killed run";
  } else if (resume && fs::is_directory(target_, ec)) {
    // A finished run: its point folders (not its top-level files, which this run rewrites).
    fs::create_directories(staging_, ec);
    for (const auto& e : fs::directory_iterator(target_, ec))
      if (e.is_directory()) fs::copy(e.path(), staging_ / e.path().filename(), fs::copy_options::recursive, ec);
    if (!ec) resumed_from_ = "the previous results";
  }
  ec.clear();
  fs::create_directories(staging_, ec);
  if (ec) {
    ::close(lock_fd_);
    lock_fd_ = -1;
    throw InputError(where + ": cannot create " + staging_.string() + ": " + ec.message());
  }
}

ResultsFolder::~ResultsFolder() {
  std::error_code ec;
  if (!committed_ && !staging_.empty()) fs::remove_all(staging_, ec);
  if (lock_fd_ >= 0) ::close(lock_fd_);  // releases the flock
}

void ResultsFolder::commit() {
  std::error_code ec;
  if (fs::exists(target_, ec)) {
    // One atomic exchange: the target is the old run or the new one at every instant.
    if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, target_.c_str(), RENAME_EXCHANGE) != 0)
      throw std::runtime_error("cannot replace " + target_.string() + " with " + staging_.string() + ": " +
                               std::strerror(errno));
    fs::remove_all(staging_, ec);  // now the old run
  } else {
    fs::rename(staging_, target_);
  }
  committed_ = true;
}

}  // namespace shroudsim::io
