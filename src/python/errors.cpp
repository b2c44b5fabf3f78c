#include "python/errors.hpp"

#include <exception>
#include <new>
#include <regex>
#include <stdexcept>

#include "core/error.hpp"

namespace shroudsim::python {
namespace {

// The classes, created once at import (the module lives as long as the interpreter).
PyObject* g_error = nullptr;
PyObject* g_input_error = nullptr;
PyObject* g_numerical_error = nullptr;

PyObject* new_class(py::module_& m, const char* name, PyObject* base, const char* doc) {
  const std::string qualified = std::string("shroudsim.") + name;
  PyObject* cls = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, base, nullptr);
  if (!cls) throw py::error_already_set();
  // Every instance answers these, None unless the message names them.
  for (const char* attr : {"file", "line", "column", "key", "result"})
    if (PyObject_SetAttrString(cls, attr, Py_None) != 0) throw py::error_already_set();
  m.add_object(name, py::handle(cls));
  return cls;
}

py::object optional_object(const std::optional<std::string>& v) { return v ? py::object(py::str(*v)) : py::none(); }
py::object optional_object(const std::optional<int>& v) { return v ? py::object(py::int_(*v)) : py::none(); }

void set_error(PyObject* cls, const std::string& message, const ErrorLocation& where, const py::object& result) {
  py::object e = py::reinterpret_borrow<py::object>(cls)(message);
  e.attr("file") = optional_object(where.file);
  e.attr("line") = optional_object(where.line);
  e.attr("column") = optional_object(where.column);
  e.attr("key") = optional_object(where.key);
  e.attr("result") = result;
  PyErr_SetObject(cls, e.ptr());
}

}  // namespace

ErrorLocation locate_input_error(const std::string& message, const std::vector<std::string>& known_files,
                                 const std::map<std::string, std::string>* locations) {
  ErrorLocation w;
  std::string rest;
  for (const auto& f : known_files)
    if (!f.empty() && message.size() > f.size() && message.compare(0, f.size(), f) == 0 && message[f.size()] == ':') {
      w.file = f;
      rest = message.substr(f.size());
      break;
    }
  std::smatch m;
  static const std::regex positioned(R"(^(.+?):(\d+):(\d+): )");
  static const std::regex named(R"(^(.+?): )");
  if (!w.file && message.rfind("--set ", 0) != 0) {
    // No known file: "<file>:<line>:<col>: " or "<file>: " (a message about --set names none).
    if (std::regex_search(message, m, positioned) || std::regex_search(message, m, named)) {
      w.file = m[1].str();
      rest = message.substr(m[1].length());
    }
  }
  if (!w.file) rest = ": " + message;
  static const std::regex position(R"(^:(\d+):(\d+): )");
  if (std::regex_search(rest, m, position)) {
    w.line = std::stoi(m[1].str());
    w.column = std::stoi(m[2].str());
    rest = rest.substr(m[0].length());
  } else if (rest.rfind(": ", 0) == 0) {
    rest = rest.substr(2);
  }
  // The key: "--set <key>=", "unknown key '<key>'", "<key> = <value> violates", "<key>: ...",
  // "<dotted.key> is ...", "[<section>]: ..."; else the key the case read at that position.
  static const std::regex set(R"(^--set ([^=\s]+)=)");
  static const std::regex unknown(R"(^unknown key '([^']+)')");
  // A dotted key leads the message ("structure.mass is required ...") as well as a value.
  static const std::regex dotted(R"(^([A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z0-9_]+)+)(?: = |:| ))");
  static const std::regex plain(R"(^([A-Za-z_][A-Za-z0-9_]*)(?: = |: expected))");
  static const std::regex section(R"(^\[([A-Za-z0-9_.]+)\])");
  for (const std::regex* r : {&set, &unknown, &dotted, &plain, &section})
    if (std::regex_search(rest, m, *r)) {
      w.key = m[1].str();
      break;
    }
  if (!w.key && w.file && w.line && locations) {
    const std::string at = *w.file + ":" + std::to_string(*w.line) + ":" + std::to_string(w.column.value_or(0));
    for (const auto& [key, where] : *locations)
      if (where == at) {
        w.key = key;
        break;
      }
  }
  return w;
}

void register_errors(py::module_& m) {
  g_error = new_class(m, "Error", PyExc_Exception,
                      "A shroudsim error (the command line's exit status 1); base of InputError and NumericalError.");
  g_input_error = new_class(m, "InputError", g_error,
                            "Bad input (the command line's exit status 2): the case, an override, the mesh, the out "
                            "folder. Attributes file, line, column, key (None where the message names none).");
  g_numerical_error = new_class(m, "NumericalError", g_error,
                                "The numerics could not deliver (the command line's exit status 3). Attribute "
                                "result: what the stage computed (the result files' content), or None.");
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      set_input_error(e.what());
    } catch (const NumericalError& e) {
      set_numerical_error(e.what(), py::none());
    } catch (const py::error_already_set&) {
      throw;  // a Python error: pybind11 restores it
    } catch (const py::builtin_exception&) {
      throw;  // pybind11's own (TypeError, ...)
    } catch (const std::bad_alloc&) {
      throw;  // MemoryError
    } catch (const std::exception& e) {
      set_error(g_error, e.what(), {}, py::none());
    }
  });
}

void set_input_error(const std::string& message, const std::vector<std::string>& known_files,
                     const std::map<std::string, std::string>* locations, bool locate) {
  set_error(g_input_error, message, locate ? locate_input_error(message, known_files, locations) : ErrorLocation{},
            py::none());
}

void set_numerical_error(const std::string& message, const py::object& result) {
  set_error(g_numerical_error, message, {}, result);
}

}  // namespace shroudsim::python
