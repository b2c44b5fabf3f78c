#pragma once
// The command line's errors as Python exceptions:
//   shroudsim.Error(Exception)       anything the command line reports as "error" (exit 1)
//   shroudsim.InputError(Error)      io InputError: bad case, override, mesh, out folder (exit 2)
//   shroudsim.NumericalError(Error)  NumericalError: the numerics could not deliver (exit 3)
// str(e) is the message the command line prints after "shroudsim: error: " (or "shroudsim:
// numerics failed: "). Every instance has the attributes file, line, column and key (None
// where the message names none), parsed from the message's "<file>:<line>:<column>: <key>"
// or "<file>: --set <key>=<value>:" head; NumericalError also has result, the partial result
// of the stage (what the result files hold), or None.
#include <pybind11/pybind11.h>

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace shroudsim::python {

namespace py = pybind11;

/// Where an input error points, as far as its message says.
struct ErrorLocation {
  std::optional<std::string> file, key;
  std::optional<int> line, column;
};

/// The location in an InputError message. known_files: the case file as named (tried first,
/// so a path holding ':' is taken whole); locations: a parsed case's key -> "file:line:col"
/// (a message that names a position but no key gets the key read there).
ErrorLocation locate_input_error(const std::string& message, const std::vector<std::string>& known_files = {},
                                 const std::map<std::string, std::string>* locations = nullptr);

/// Creates the exception classes in the module and registers the translation of
/// InputError, NumericalError and other std::exception into them.
void register_errors(py::module_& m);

/// Sets shroudsim.InputError for `message` as the current Python error, with its location
/// (locate = false: a message about no case file, e.g. the out folder's).
void set_input_error(const std::string& message, const std::vector<std::string>& known_files = {},
                     const std::map<std::string, std::string>* locations = nullptr, bool locate = true);
/// Sets shroudsim.NumericalError(message) with attribute result as the current Python error.
void set_numerical_error(const std::string& message, const py::object& result);

}  // namespace shroudsim::python
