#pragma once
// Conversions between Python values and what the pipeline reads and writes: a case given as a
// Python dict becomes TOML text (parsed by io::parse_case like a case file), overrides become
// the command line's "KEY=VALUE" strings, result tables (CSV) become numpy arrays, and the run
// report (JSON) becomes Python dicts and lists.
#include <pybind11/pybind11.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace shroudsim::python {

namespace py = pybind11;

/// The TOML text of a case given as a dict: top-level values first, then one [section] per
/// nested dict, one line per key in the dict's order (so a message's line number points at
/// the key). Values: bool, int, float, str, lists and dicts of them, numpy scalars and
/// arrays. `file` names the case in messages: InputError "<file>: <key>: ..." for a value
/// TOML cannot hold (None, an object).
std::string dict_to_toml(const py::dict& case_dict, const std::string& file);

/// Overrides as the command line's --set strings, in order: None (none), a str ("KEY=VALUE"),
/// a list of such strings, or a dict {dotted key: value} (the value written as TOML: a Python
/// str becomes a TOML string). Throws InputError (naming `file`) for anything else.
std::vector<std::string> override_strings(const py::handle& overrides, const std::string& file);

/// A CSV result file as {column: numpy array}: integer columns as int64, numbers as float64
/// (the files hold the shortest text that reads back to the computed double, so these are
/// the computed values bit for bit), anything else as an array of str. Columns in file order.
py::dict read_csv_table(const std::filesystem::path& file);

/// Every *.csv of a folder (not its subfolders) by file stem: {"frf": {...}, "peaks": {...}}.
py::dict read_csv_tables(const std::filesystem::path& folder);

/// A JSON value as Python objects (dict, list, str, int, float, bool, None).
py::object to_python(const nlohmann::json& value);

}  // namespace shroudsim::python
