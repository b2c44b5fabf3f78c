#include "python/convert.hpp"

#include <pybind11/numpy.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "core/format.hpp"

namespace shroudsim::python {
namespace {

namespace fs = std::filesystem;

/// TOML's bare keys: A-Z a-z 0-9 _ -; anything else is written as a quoted key.
bool is_bare_key(const std::string& key) {
  return !key.empty() && std::all_of(key.begin(), key.end(),
                                     [](unsigned char ch) { return std::isalnum(ch) != 0 || ch == '_' || ch == '-'; });
}

/// A TOML basic string: quotes, backslashes and control characters escaped.
std::string quoted(const std::string& text) {
  std::string s = "\"";
  for (const unsigned char ch : text) {
    switch (ch) {
      case '"': s += "\\\""; break;
      case '\\': s += "\\\\"; break;
      case '\n': s += "\\n"; break;
      case '\t': s += "\\t"; break;
      case '\r': s += "\\r"; break;
      default:
        if (ch < 0x20 || ch == 0x7f) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", ch);
          s += buf;
        } else {
          s += static_cast<char>(ch);
        }
    }
  }
  return s + "\"";
}

std::string key_text(const std::string& key) { return is_bare_key(key) ? key : quoted(key); }

/// A TOML float: the shortest text that reads back to the same double, with a decimal point
/// or an exponent so that TOML reads a float (5.0, not the integer 5).
std::string float_text(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  std::string s = shortest(v);
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

/// A column in a unit (frequency_hz, amplitude_m, speed_rpm, ...) holds numbers even when
/// every value of a file happens to be written without a decimal point (0, 1500).
bool has_unit(const std::string& column) {
  for (const char* unit : {"_m", "_m2", "_m3", "_hz", "_n", "_rpm", "_pa", "_s", "_seconds", "_deg", "_mib"}) {
    const std::string u(unit);
    if (column.size() > u.size() && column.compare(column.size() - u.size(), u.size(), u) == 0) return true;
  }
  return false;
}

std::string type_of(const py::handle& value) { return py::str(py::type::of(value).attr("__name__")); }

/// Python value -> TOML value text (inline: arrays as [...], dicts as {...}).
std::string value_text(const py::handle& value, const std::string& key, const std::string& file) {
  // numpy: arrays as nested lists, scalars as Python scalars.
  if (py::hasattr(value, "dtype") && py::hasattr(value, "tolist")) return value_text(value.attr("tolist")(), key, file);
  if (py::isinstance<py::bool_>(value)) return value.cast<bool>() ? "true" : "false";
  if (py::isinstance<py::int_>(value)) {
    try {
      return std::to_string(value.cast<long long>());
    } catch (const py::cast_error&) {
      throw InputError(file + ": " + key + ": the integer " + std::string(py::str(value)) +
                       " does not fit in 64 bits (TOML's integers)");
    }
  }
  if (py::isinstance<py::float_>(value)) return float_text(value.cast<double>());
  if (py::isinstance<py::str>(value)) return quoted(value.cast<std::string>());
  if (py::isinstance<py::dict>(value)) {
    std::string s = "{";
    bool first = true;
    for (const auto& [k, v] : value.cast<py::dict>()) {
      if (!py::isinstance<py::str>(k))
        throw InputError(file + ": " + key + ": keys must be strings, got " + type_of(k) + " " +
                         std::string(py::repr(k)));
      const std::string name = k.cast<std::string>();
      s += (first ? " " : ", ") + key_text(name) + " = " + value_text(v, key + "." + name, file);
      first = false;
    }
    return s + (first ? "}" : " }");
  }
  if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    std::string s = "[";
    std::size_t i = 0;
    for (const auto& item : value) {
      s += (i ? ", " : "") + value_text(item, key + "[" + std::to_string(i) + "]", file);
      ++i;
    }
    return s + "]";
  }
  throw InputError(file + ": " + key + ": " + (value.is_none() ? std::string("None") : "a " + type_of(value)) +
                   " cannot be written as TOML (bool, int, float, str, and lists and dicts of them can)");
}

}  // namespace

std::string dict_to_toml(const py::dict& case_dict, const std::string& file) {
  // TOML needs every top-level value before the first [section] header.
  std::ostringstream top, sections;
  for (const auto& [k, v] : case_dict) {
    if (!py::isinstance<py::str>(k))
      throw InputError(file + ": keys must be strings, got " + type_of(k) + " " + std::string(py::repr(k)));
    const std::string name = k.cast<std::string>();
    if (!py::isinstance<py::dict>(v)) {
      top << key_text(name) << " = " << value_text(v, name, file) << "\n";
      continue;
    }
    sections << "\n[" << key_text(name) << "]\n";
    for (const auto& [sk, sv] : v.cast<py::dict>()) {
      if (!py::isinstance<py::str>(sk))
        throw InputError(file + ": " + name + ": keys must be strings, got " + type_of(sk) + " " +
                         std::string(py::repr(sk)));
      const std::string sub = sk.cast<std::string>();
      sections << key_text(sub) << " = " << value_text(sv, name + "." + sub, file) << "\n";
    }
  }
  return top.str() + sections.str();
}

std::vector<std::string> override_strings(const py::handle& overrides, const std::string& file) {
  std::vector<std::string> sets;
  if (overrides.is_none()) return sets;
  if (py::isinstance<py::str>(overrides)) return {overrides.cast<std::string>()};
  if (py::isinstance<py::dict>(overrides)) {
    for (const auto& [k, v] : overrides.cast<py::dict>()) {
      if (!py::isinstance<py::str>(k))
        throw InputError(file + ": override keys must be dotted key strings, got " + type_of(k) + " " +
                         std::string(py::repr(k)));
      const std::string key = k.cast<std::string>();
      sets.push_back(key + "=" + value_text(v, key, file));
    }
    return sets;
  }
  if (py::isinstance<py::list>(overrides) || py::isinstance<py::tuple>(overrides)) {
    for (const auto& item : overrides) {
      if (!py::isinstance<py::str>(item))
        throw InputError(file + ": overrides: expected \"KEY=VALUE\" strings, got " + type_of(item) + " " +
                         std::string(py::repr(item)));
      sets.push_back(item.cast<std::string>());
    }
    return sets;
  }
  throw InputError(file + ": overrides: expected a dict {key: value} or a list of \"KEY=VALUE\" strings, got " +
                   type_of(overrides));
}

py::dict read_csv_table(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + file.string());
  auto split = [](const std::string& line) {
    std::vector<std::string> cells;
    std::size_t start = 0;
    while (true) {
      const std::size_t comma = line.find(',', start);
      cells.push_back(line.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    return cells;
  };
  std::string line;
  py::dict table;
  if (!std::getline(in, line)) return table;
  const std::vector<std::string> header = split(line);
  std::vector<std::vector<std::string>> columns(header.size());
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::vector<std::string> cells = split(line);
    cells.resize(header.size());
    for (std::size_t c = 0; c < header.size(); ++c) columns[c].push_back(std::move(cells[c]));
  }
  for (std::size_t c = 0; c < header.size(); ++c) {
    const std::vector<std::string>& cells = columns[c];
    const auto n = static_cast<py::ssize_t>(cells.size());
    // The narrowest type every cell of the column reads as: integer, then number, else text.
    bool integers = !has_unit(header[c]), numbers = true;
    std::vector<double> values(cells.size());
    std::vector<std::int64_t> counts(cells.size());
    for (std::size_t i = 0; i < cells.size() && numbers; ++i) {
      const char* text = cells[i].c_str();
      char* end = nullptr;
      if (integers) {
        errno = 0;
        counts[i] = std::strtoll(text, &end, 10);
        integers = !cells[i].empty() && *end == '\0' && errno == 0;
      }
      values[i] = std::strtod(text, &end);
      numbers = !cells[i].empty() && *end == '\0';
    }
    if (numbers && integers) {
      py::array_t<std::int64_t> a(n);
      std::copy(counts.begin(), counts.end(), a.mutable_data());
      table[py::str(header[c])] = a;
    } else if (numbers) {
      py::array_t<double> a(n);
      std::copy(values.begin(), values.end(), a.mutable_data());
      table[py::str(header[c])] = a;
    } else {
      py::list texts;
      for (const auto& s : cells) texts.append(py::str(s));
      table[py::str(header[c])] = py::module_::import("numpy").attr("array")(texts, py::arg("dtype") = "str");
    }
  }
  return table;
}

py::dict read_csv_tables(const fs::path& folder) {
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec))
    if (entry.is_regular_file() && entry.path().extension() == ".csv") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  py::dict tables;
  for (const auto& f : files) tables[py::str(f.stem().string())] = read_csv_table(f);
  return tables;
}

py::object to_python(const nlohmann::json& value) {
  // The json module reads what nlohmann writes (non-finite numbers are written as null).
  return py::module_::import("json").attr("loads")(value.dump());
}

}  // namespace shroudsim::python
