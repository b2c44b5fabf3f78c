#pragma once
// Errors at the boundaries of shroudsim.
//  - InputError: the user's input is wrong (case file, --set, mesh). The CLI maps it to
//    exit status 2 and prints what() verbatim, which already names file:line:col and key.
//  - NumericalError: the numerics could not deliver (exit status 3).
//  - SHROUDSIM_CHECK: always-on precondition checks (programming errors) -> std::logic_error.
//  - SHROUDSIM_ASSERT: debug-only checks.
#include <stdexcept>
#include <string>

namespace shroudsim {

/// Bad user input. The message is complete ("file:line:col: key = value violates: ...").
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

/// The numerics failed (no convergence, singular system). Exit status 3.
class NumericalError : public std::runtime_error {
 public:
  explicit NumericalError(const std::string& message) : std::runtime_error(message) {}
};

namespace detail {
[[noreturn]] void check_failed(const char* condition, const std::string& message, const char* file, int line);
}  // namespace detail

}  // namespace shroudsim

#define SHROUDSIM_CHECK(cond, msg)                                                    \
  do {                                                                                \
    if (!(cond)) ::shroudsim::detail::check_failed(#cond, (msg), __FILE__, __LINE__); \
  } while (false)

#ifndef NDEBUG
#define SHROUDSIM_ASSERT(cond, msg) SHROUDSIM_CHECK(cond, msg)
#else
#define SHROUDSIM_ASSERT(cond, msg) \
  do {                              \
  } while (false)
#endif
