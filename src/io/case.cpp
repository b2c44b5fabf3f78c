#include "io/case.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <Eigen/Eigenvalues>
#include <Eigen/Dense>
#include <toml++/toml.h>

#include "core/error.hpp"
#include "io/schema.hpp"

namespace shroudsim::io {
namespace {

namespace fs = std::filesystem;

/// Levenshtein distance, for "did you mean" suggestions.
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string suggestion(const std::string& key) {
  std::string best;
  std::size_t best_d = 4;
  for (const auto& spec : case_schema()) {
    const std::size_t d = edit_distance(key, spec.key);
    if (d < best_d) best_d = d, best = spec.key;
  }
  if (best.empty()) {
    // Same section, and the spec's name contains the given name ("preload" -> "normal_preload").
    const auto dot = key.rfind('.');
    const std::string section = dot == std::string::npos ? "" : key.substr(0, dot + 1);
    const std::string name = key.substr(dot == std::string::npos ? 0 : dot + 1);
    for (const auto& spec : case_schema())
      if (name.size() >= 3 && spec.key.rfind(section, 0) == 0 && spec.key.find(name, section.size()) != std::string::npos) {
        best = spec.key;
        break;
      }
  }
  return best.empty() ? "" : " (did you mean '" + best + "'?)";
}

std::string value_text(const toml::node& node) {
  std::ostringstream s;
  if (auto str = node.as_string()) {
    s << '"' << str->get() << '"';
  } else if (node.is_table()) {
    s << "{...}";
  } else {
    node.visit([&](auto&& v) {
      if constexpr (toml::is_array<decltype(v)>) {
        s << toml::toml_formatter{v, toml::format_flags::none};
      } else {
        s << v;
      }
    });
  }
  std::string out = s.str();
  if (out.size() > 60) out = out.substr(0, 57) + "...";
  return out;
}

std::string type_name(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a number";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::array: return "an array";
    case toml::node_type::table: return "a table";
    default: return "a date/time";
  }
}

/// Reads typed values out of a table with defaults inserted, reporting every problem as
/// "file:line:col: key ..." (or "--set key=value: ..." for overridden keys).
class Reader {
 public:
  Reader(toml::table& root, fs::path file, std::map<std::string, std::string> overridden)
      : root_(root), file_(std::move(file)), overridden_(std::move(overridden)) {}

  [[noreturn]] void fail(const std::string& key, const toml::node* node, const std::string& what) const {
    throw InputError(where(key, node) + what);
  }
  [[noreturn]] void violates(const std::string& key, const toml::node& node, const std::string& constraint) const {
    fail(key, &node, key + " = " + value_text(node) + " violates: " + constraint);
  }
  std::string where(const std::string& key, const toml::node* node) const {
    auto it = overridden_.find(key);
    if (it != overridden_.end()) return file_.string() + ": --set " + key + "=" + it->second + ": ";
    if (node && node->source().begin.line > 0)
      return file_.string() + ":" + std::to_string(node->source().begin.line) + ":" +
             std::to_string(node->source().begin.column) + ": ";
    return file_.string() + ": ";
  }

  const toml::node& node(const std::string& key) const {
    const toml::node* n = root_.at_path(key).node();
    SHROUDSIM_CHECK(n != nullptr, "schema key with a default: " + key);
    std::string w = where(key, n);
    locations_[key] = w.substr(0, w.size() - 2);  // without the trailing ": "
    return *n;
  }
  const std::map<std::string, std::string>& locations() const { return locations_; }

  double number(const std::string& key, const std::function<std::optional<std::string>(double)>& check = {}) const {
    const toml::node& n = node(key);
    double v = 0.0;
    if (auto i = n.as_integer()) v = static_cast<double>(i->get());
    else if (auto f = n.as_floating_point()) v = f->get();
    else fail(key, &n, key + ": expected a number, got " + type_name(n) + " " + value_text(n));
    if (!std::isfinite(v)) violates(key, n, "a finite number");
    if (check)
      if (auto c = check(v)) violates(key, n, *c);
    return v;
  }

  int integer(const std::string& key, const std::function<std::optional<std::string>(long long)>& check = {}) const {
    const toml::node& n = node(key);
    auto i = n.as_integer();
    if (!i) fail(key, &n, key + ": expected an integer, got " + type_name(n) + " " + value_text(n));
    if (check)
      if (auto c = check(i->get())) violates(key, n, *c);
    if (i->get() > 1'000'000'000 || i->get() < -1'000'000'000) violates(key, n, "|value| <= 1e9");
    return static_cast<int>(i->get());
  }

  bool boolean(const std::string& key) const {
    const toml::node& n = node(key);
    auto b = n.as_boolean();
    if (!b) fail(key, &n, key + ": expected true or false, got " + type_name(n) + " " + value_text(n));
    return b->get();
  }

  std::string string(const std::string& key, const std::vector<std::string>& one_of = {}) const {
    const toml::node& n = node(key);
    auto s = n.as_string();
    if (!s) fail(key, &n, key + ": expected a string, got " + type_name(n) + " " + value_text(n));
    if (!one_of.empty() && std::find(one_of.begin(), one_of.end(), s->get()) == one_of.end()) {
      std::string list;
      for (const auto& o : one_of) list += (list.empty() ? "" : " | ") + ("\"" + o + "\"");
      violates(key, n, "one of " + list);
    }
    return s->get();
  }

  std::vector<double> numbers(const std::string& key, const toml::node& n) const {
    auto a = n.as_array();
    if (!a) fail(key, &n, key + ": expected an array of numbers, got " + type_name(n) + " " + value_text(n));
    std::vector<double> out;
    for (const auto& e : *a) {
      if (auto i = e.as_integer()) out.push_back(static_cast<double>(i->get()));
      else if (auto f = e.as_floating_point()) out.push_back(f->get());
      else fail(key, &e, key + ": expected numbers in the array, got " + type_name(e) + " " + value_text(e));
      if (!std::isfinite(out.back())) violates(key, e, "finite numbers");
    }
    return out;
  }
  std::vector<double> numbers(const std::string& key) const { return numbers(key, node(key)); }

  std::vector<int> integers(const std::string& key, const toml::node& n) const {
    auto a = n.as_array();
    if (!a) fail(key, &n, key + ": expected an array of integers, got " + type_name(n) + " " + value_text(n));
    std::vector<int> out;
    for (const auto& e : *a) {
      auto i = e.as_integer();
      if (!i) fail(key, &e, key + ": expected integers in the array, got " + type_name(e) + " " + value_text(e));
      if (std::llabs(i->get()) > 1'000'000'000) violates(key, e, "|value| <= 1e9");
      out.push_back(static_cast<int>(i->get()));
    }
    return out;
  }

  std::array<double, 3> vec3(const std::string& key) const {
    const auto v = numbers(key);
    if (v.size() != 3) violates(key, node(key), "exactly 3 numbers [x, y, z]");
    return {v[0], v[1], v[2]};
  }

  Eigen::MatrixXd matrix(const std::string& key) const {
    const toml::node& n = node(key);
    auto a = n.as_array();
    if (!a) fail(key, &n, key + ": expected an array of rows, got " + type_name(n));
    const int rows = static_cast<int>(a->size());
    Eigen::MatrixXd m(rows, rows);
    for (int r = 0; r < rows; ++r) {
      const auto row = numbers(key, (*a)[static_cast<std::size_t>(r)]);
      if (static_cast<int>(row.size()) != rows) violates(key, (*a)[static_cast<std::size_t>(r)], "a square matrix (n rows of n numbers)");
      for (int c = 0; c < rows; ++c) m(r, c) = row[static_cast<std::size_t>(c)];
    }
    return m;
  }

  std::vector<MotionHarmonic> motion(const std::string& key) const {
    const toml::node& n = node(key);
    auto a = n.as_array();
    if (!a) fail(key, &n, key + ": expected rows [harmonic, cosine, sine], got " + type_name(n));
    std::vector<MotionHarmonic> out;
    for (const auto& row : *a) {
      const auto v = numbers(key, row);
      if (v.size() != 3) violates(key, row, "rows of 3 numbers [harmonic, cosine, sine]");
      if (v[0] < 0 || v[0] != std::floor(v[0]) || v[0] > 10000) violates(key, row, "harmonic an integer in 0..10000");
      out.push_back({static_cast<int>(v[0]), v[1], v[2]});
    }
    return out;
  }

  const fs::path& file() const { return file_; }
  toml::table& root() { return root_; }

 private:
  toml::table& root_;
  fs::path file_;
  std::map<std::string, std::string> overridden_;
  mutable std::map<std::string, std::string> locations_;
};

std::optional<std::string> positive(double v) { return v > 0 ? std::nullopt : std::optional<std::string>("> 0"); }
std::optional<std::string> non_negative(double v) { return v >= 0 ? std::nullopt : std::optional<std::string>(">= 0"); }
auto in_range_int(long long lo, long long hi) {
  return [lo, hi](long long v) -> std::optional<std::string> {
    if (v >= lo && v <= hi) return std::nullopt;
    return std::to_string(lo) + " <= value <= " + std::to_string(hi);
  };
}

/// Splits "a.b.c=value" into the key and the TOML value text.
std::pair<std::string, std::string> split_override(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("--set " + text + ": expected KEY=VALUE with a dotted key, e.g. hbm.harmonics=7");
  auto trim = [](std::string s) {
    s.erase(0, s.find_first_not_of(" \t"));
    s.erase(s.find_last_not_of(" \t") + 1);
    return s;
  };
  return {trim(text.substr(0, eq)), trim(text.substr(eq + 1))};
}

/// Parses a --set value as TOML; a bare word that is no TOML value is taken as a string.
toml::node_view<toml::node> parse_value(toml::table& holder, const std::string& key, const std::string& value) {
  try {
    holder = toml::parse("v = " + value);
  } catch (const toml::parse_error&) {
    const bool bare = !value.empty() && value.find_first_of("\"'[]{}=\n") == std::string::npos;
    if (!bare) throw InputError("--set " + key + "=" + value + ": not a TOML value (quote strings, e.g. \"text\")");
    holder = toml::table{{"v", value}};
  }
  return holder["v"];
}

/// Every key path below root that the schema does not know, with its node.
void find_unknown(const toml::table& table, const std::string& prefix, const Reader& reader) {
  for (const auto& [k, v] : table) {
    const std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (prefix.empty() && key == "expect") {
      auto t = v.as_table();
      if (!t) reader.fail(key, &v, "expect: expected a table of numbers");
      for (const auto& [ek, ev] : *t)
        if (!ev.is_number())
          reader.fail(key + "." + std::string(ek.str()), &ev, "expect." + std::string(ek.str()) + ": expected a number");
      continue;
    }
    if (find_key(key)) continue;
    const bool is_section = prefix.empty() && std::any_of(case_sections().begin(), case_sections().end(),
                                                          [&](const auto& s) { return s.first == key; });
    if (is_section) {
      auto t = v.as_table();
      if (!t) reader.fail(key, &v, "[" + key + "] must be a table, got " + type_name(v));
      find_unknown(*t, key, reader);
      continue;
    }
    reader.fail(key, &v, "unknown key '" + key + "'" + suggestion(key));
  }
}

/// Inserts the schema default of every key the document does not set.
void insert_defaults(toml::table& root) {
  for (const auto& spec : case_schema()) {
    if (root.at_path(spec.key).node()) continue;
    toml::table parsed = toml::parse("v = " + spec.default_toml);
    const auto dot = spec.key.rfind('.');
    toml::table* target = &root;
    if (dot != std::string::npos) {
      const std::string section = spec.key.substr(0, dot);
      if (!root.contains(section)) root.insert(section, toml::table{});
      target = root[section].as_table();
      SHROUDSIM_CHECK(target != nullptr, "section is a table (checked before)");
    }
    target->insert(spec.key.substr(dot == std::string::npos ? 0 : dot + 1), *parsed["v"].node());
  }
}

void read_contact_elements(Reader& r, Case& c) {
  const std::string key = "contact.elements";
  const toml::node& n = r.node(key);
  auto a = n.as_array();
  if (!a) r.fail(key, &n, key + ": expected an array of tables ([[contact.elements]])");
  static const std::set<std::string> dof_keys = {"x_dof", "y_dof", "z_dof", "other_x_dof", "other_y_dof", "other_z_dof"};
  static const std::set<std::string> value_keys = {"friction_coefficient", "normal_stiffness", "tangential_stiffness",
                                                   "normal_preload", "frame_angle_deg"};
  for (const auto& e : *a) {
    auto t = e.as_table();
    if (!t) r.fail(key, &e, key + ": expected tables ([[contact.elements]])");
    ContactElement el;
    for (const auto& [k, v] : *t) {
      const std::string name(k.str());
      const std::string full = key + "." + name;
      if (dof_keys.count(name)) {
        auto i = v.as_integer();
        if (!i) r.fail(full, &v, full + ": expected an integer DOF index, got " + type_name(v));
        if (i->get() < 0 || i->get() > 1'000'000) r.violates(full, v, "0 <= dof");
        const int d = static_cast<int>(i->get());
        if (name == "x_dof") el.x_dof = d;
        else if (name == "y_dof") el.y_dof = d;
        else if (name == "z_dof") el.z_dof = d;
        else if (name == "other_x_dof") el.other_x_dof = d;
        else if (name == "other_y_dof") el.other_y_dof = d;
        else el.other_z_dof = d;
      } else if (value_keys.count(name)) {
        double d = 0;
        if (auto i = v.as_integer()) d = static_cast<double>(i->get());
        else if (auto f = v.as_floating_point()) d = f->get();
        else r.fail(full, &v, full + ": expected a number, got " + type_name(v));
        if (!std::isfinite(d)) r.violates(full, v, "a finite number");
        if ((name == "normal_stiffness" || name == "tangential_stiffness") && d <= 0) r.violates(full, v, "> 0");
        if (name == "friction_coefficient" && d < 0) r.violates(full, v, ">= 0");
        if (name == "friction_coefficient") el.friction_coefficient = d;
        else if (name == "normal_stiffness") el.normal_stiffness = d;
        else if (name == "tangential_stiffness") el.tangential_stiffness = d;
        else if (name == "normal_preload") el.normal_preload = d;
        else el.frame_angle_deg = d;
      } else {
        r.fail(full, &v, "unknown key '" + full + "' (contact elements take x_dof, y_dof, z_dof, other_x_dof, "
                         "other_y_dof, other_z_dof, friction_coefficient, normal_stiffness, tangential_stiffness, "
                         "normal_preload, frame_angle_deg)");
      }
    }
    if (el.x_dof < 0 && el.y_dof < 0 && el.z_dof < 0) r.fail(key, &e, key + ": an element needs at least one of x_dof, y_dof, z_dof");
    c.contact.elements.push_back(el);
  }
}

void read_all(Reader& r, Case& c) {
  c.name = r.string("name");
  if (c.name.empty() || c.name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-.") != std::string::npos ||
      c.name == "." || c.name == "..")
    r.violates("name", r.node("name"), "non-empty, only letters, digits, _ - .");

  auto& st = c.structure;
  st.type = r.string("structure.type", {"sector", "lumped"});
  const bool lumped = st.type == "lumped";
  st.sectors = r.integer("structure.sectors", in_range_int(lumped ? 1 : 2, 1000));
  const std::string mesh = r.string("structure.mesh");
  if (!mesh.empty()) {
    fs::path p(mesh);
    if (p.is_relative()) p = c.directory / p;
    st.mesh = p.lexically_normal();
    if (!fs::exists(st.mesh)) r.violates("structure.mesh", r.node("structure.mesh"), "an existing mesh file (looked for " + st.mesh.string() + ")");
  }
  st.mass = r.matrix("structure.mass");
  st.stiffness = r.matrix("structure.stiffness");
  st.damping = r.matrix("structure.damping");
  if (lumped) {
    const auto n = st.mass.rows();
    if (n == 0) r.fail("structure.mass", &r.node("structure.mass"), "structure.mass is required when structure.type = \"lumped\"");
    if (st.stiffness.rows() != n) r.violates("structure.stiffness", r.node("structure.stiffness"), "the same size as structure.mass (" + std::to_string(n) + " x " + std::to_string(n) + ")");
    if (st.damping.rows() != 0 && st.damping.rows() != n) r.violates("structure.damping", r.node("structure.damping"), "[] or the size of structure.mass");
    for (const char* k : {"structure.mass", "structure.stiffness", "structure.damping"}) {
      const Eigen::MatrixXd& m = std::string(k) == "structure.mass" ? st.mass : std::string(k) == "structure.stiffness" ? st.stiffness : st.damping;
      if (m.size() && (m - m.transpose()).norm() > 1e-12 * m.norm()) r.violates(k, r.node(k), "a symmetric matrix");
    }
    Eigen::LLT<Eigen::MatrixXd> llt(st.mass);
    if (llt.info() != Eigen::Success) r.violates("structure.mass", r.node("structure.mass"), "positive definite");
    // Stiffness and damping: positive semidefinite (a negative eigenvalue is an energy
    // source, not a structure); tolerance: round-off of the largest eigenvalue.
    for (const char* k : {"structure.stiffness", "structure.damping"}) {
      const Eigen::MatrixXd& m = std::string(k) == "structure.stiffness" ? st.stiffness : st.damping;
      if (m.size() == 0) continue;
      const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(m, Eigen::EigenvaluesOnly).eigenvalues();
      if (ev.minCoeff() < -1e-12 * std::max(ev.cwiseAbs().maxCoeff(), 1e-300))
        r.violates(k, r.node(k), "positive semidefinite (its smallest eigenvalue is " + std::to_string(ev.minCoeff()) + ")");
    }
  } else {
    for (const char* k : {"structure.mass", "structure.stiffness", "structure.damping"})
      if (r.node(k).as_array() && !r.node(k).as_array()->empty()) r.fail(k, &r.node(k), std::string(k) + " is only for structure.type = \"lumped\"");
  }

  auto& g = c.geometry;
  g.hub_radius = r.number("geometry.hub_radius", positive);
  g.disk_outer_radius = r.number("geometry.disk_outer_radius", positive);
  if (g.disk_outer_radius <= g.hub_radius) r.violates("geometry.disk_outer_radius", r.node("geometry.disk_outer_radius"), "disk_outer_radius > hub_radius");
  g.disk_thickness = r.number("geometry.disk_thickness", positive);
  g.blade_length = r.number("geometry.blade_length", positive);
  g.blade_chord = r.number("geometry.blade_chord", positive);
  g.blade_thickness = r.number("geometry.blade_thickness", positive);
  if (g.blade_thickness >= g.blade_chord) r.violates("geometry.blade_thickness", r.node("geometry.blade_thickness"), "blade_thickness < blade_chord");
  g.blade_twist_deg = r.number("geometry.blade_twist_deg", [](double v) -> std::optional<std::string> {
    return std::abs(v) <= 60 ? std::nullopt : std::optional<std::string>("-60 <= blade_twist_deg <= 60");
  });
  g.shroud_thickness = r.number("geometry.shroud_thickness", positive);
  g.shroud_width = r.number("geometry.shroud_width", positive);
  g.shroud_contact_angle_deg = r.number("geometry.shroud_contact_angle_deg", [](double v) -> std::optional<std::string> {
    return v >= 0 && v < 90 ? std::nullopt : std::optional<std::string>("0 <= shroud_contact_angle_deg < 90");
  });
  g.element_order = r.integer("geometry.element_order", in_range_int(1, 2));
  g.mesh_size = r.number("geometry.mesh_size", positive);
  g.max_elements = r.number("geometry.max_elements", positive);
  if (!lumped && st.mesh.empty())
    for (const auto& [key, what] : sector_geometry(c).validate()) r.violates(key, r.node(key), what);

  auto& m = c.material;
  m.youngs_modulus = r.number("material.youngs_modulus", positive);
  m.poisson_ratio = r.number("material.poisson_ratio", [](double v) -> std::optional<std::string> {
    return v > -1.0 && v < 0.5 ? std::nullopt : std::optional<std::string>("-1 < poisson_ratio < 0.5");
  });
  m.density = r.number("material.density", positive);

  auto& mo = c.modal;
  mo.modes = r.integer("modal.modes", in_range_int(1, 2000));
  {
    const std::string key = "modal.harmonic_indices";
    const toml::node& n = r.node(key);
    if (auto s = n.as_string()) {
      if (s->get() != "all") r.violates(key, n, "\"all\" or a list of harmonic indices");
      mo.all_harmonic_indices = true;
    } else {
      mo.all_harmonic_indices = false;
      mo.harmonic_indices = r.integers(key, n);
      if (mo.harmonic_indices.empty()) r.violates(key, n, "a non-empty list (or \"all\")");
      for (int h : mo.harmonic_indices)
        if (h < 0 || h >= st.sectors) r.violates(key, n, "0 <= h < structure.sectors (" + std::to_string(st.sectors) + ")");
      std::sort(mo.harmonic_indices.begin(), mo.harmonic_indices.end());
      mo.harmonic_indices.erase(std::unique(mo.harmonic_indices.begin(), mo.harmonic_indices.end()), mo.harmonic_indices.end());
    }
  }
  mo.damping_ratio = r.number("modal.damping_ratio", [](double v) -> std::optional<std::string> {
    return v >= 0 && v < 1 ? std::nullopt : std::optional<std::string>("0 <= damping_ratio < 1");
  });
  mo.residual_flexibility = r.boolean("modal.residual_flexibility");
  mo.eigensolver = r.string("modal.eigensolver", {"block", "spectra"});
  mo.shroud = r.string("modal.shroud", {"open", "stuck", "contact"});

  auto& ca = c.campbell;
  ca.speed_rpm = r.numbers("campbell.speed_rpm");
  if (ca.speed_rpm.size() != 2 || ca.speed_rpm[0] < 0 || ca.speed_rpm[1] <= ca.speed_rpm[0])
    r.violates("campbell.speed_rpm", r.node("campbell.speed_rpm"), "[min, max] with 0 <= min < max");
  ca.speed_points = r.integer("campbell.speed_points", in_range_int(2, 10000));
  ca.engine_orders = r.integers("campbell.engine_orders", r.node("campbell.engine_orders"));
  for (int e : ca.engine_orders)
    if (e < 1) r.violates("campbell.engine_orders", r.node("campbell.engine_orders"), "engine orders >= 1");
  ca.rotating_effects = r.boolean("campbell.rotating_effects");

  c.static_contact.speed_rpm = r.number("static.speed_rpm", non_negative);
  c.static_contact.increments = r.integer("static.increments", in_range_int(1, 1000));

  auto& ex = c.excitation;
  ex.engine_order = r.integer("excitation.engine_order", in_range_int(0, 100000));
  ex.point = r.vec3("excitation.point");
  {
    const toml::node& n = r.node("excitation.force");
    if (n.is_number()) {
      if (!lumped) r.violates("excitation.force", n, "3 numbers [Fx, Fy, Fz] for a sector (one number is for lumped models)");
      ex.force = {r.number("excitation.force"), 0.0, 0.0};
    } else {
      ex.force = r.vec3("excitation.force");
    }
  }
  ex.dof = r.integer("excitation.dof", in_range_int(0, 1'000'000));
  ex.speed_rpm = r.number("excitation.speed_rpm", non_negative);
  c.response.point = r.vec3("response.point");
  c.response.dof = r.integer("response.dof", in_range_int(0, 1'000'000));
  if (lumped) {
    const int n = static_cast<int>(st.mass.rows());
    if (ex.dof >= n) r.violates("excitation.dof", r.node("excitation.dof"), "dof < " + std::to_string(n) + " (the size of structure.mass)");
    if (c.response.dof >= n) r.violates("response.dof", r.node("response.dof"), "dof < " + std::to_string(n) + " (the size of structure.mass)");
  }

  auto& co = c.contact;
  co.model = r.string("contact.model", {"full3d", "quasi3d", "1d", "1d_exact"});
  {
    const std::string key = "contact.pairs";
    const toml::node& n = r.node(key);
    if (auto s = n.as_string()) {
      if (s->get() != "all") r.violates(key, n, "\"all\" or a count >= 1");
      co.pairs = 0;
    } else {
      co.pairs = r.integer(key, in_range_int(1, 1'000'000));
    }
  }
  co.discretization = r.string("contact.discretization", {"patches", "nodes"});
  co.friction_coefficient = r.number("contact.friction_coefficient", non_negative);
  co.normal_stiffness = r.number("contact.normal_stiffness", positive);
  co.tangential_stiffness = r.number("contact.tangential_stiffness", positive);
  {
    const std::string key = "contact.normal_preload";
    const toml::node& n = r.node(key);
    if (auto sv = n.as_string()) {
      if (sv->get() != "static") r.violates(key, n, "a number (N) or \"static\"");
      if (lumped) r.violates(key, n, "a number (N): \"static\" needs an FE sector");
      co.normal_preload_static = true;
      co.normal_preload = 0.0;
    } else {
      co.normal_preload = r.number(key);
    }
  }
  co.frame_angle_deg = r.number("contact.frame_angle_deg");
  co.interference = r.number("contact.interference");
  co.tangential_update = r.string("contact.tangential_update", {"exact_linear", "radial_return"});
  read_contact_elements(r, c);
  if (!lumped && !co.elements.empty())
    r.fail("contact.elements", &r.node("contact.elements"), "contact.elements is only for structure.type = \"lumped\"");
  if (lumped) {
    const int n = static_cast<int>(st.mass.rows());
    for (const auto& e : co.elements)
      for (int d : {e.x_dof, e.y_dof, e.z_dof, e.other_x_dof, e.other_y_dof, e.other_z_dof})
        if (d >= n) r.violates("contact.elements", r.node("contact.elements"), "DOF indices < " + std::to_string(n) + " (the size of structure.mass)");
  }

  auto& h = c.hbm;
  {
    const std::string key = "hbm.harmonics";
    const toml::node& n = r.node(key);
    if (auto s = n.as_string()) {
      if (s->get() != "auto") r.violates(key, n, "an integer 1 <= H <= 200 or \"auto\"");
      h.harmonics_auto = true;
      h.harmonics = 0;
    } else {
      h.harmonics = r.integer(key, in_range_int(1, 200));
    }
  }
  {
    const std::string key = "hbm.time_samples";
    const toml::node& n = r.node(key);
    if (auto s = n.as_string()) {
      if (s->get() != "auto") r.violates(key, n, "an integer N >= 2H+1 or \"auto\"");
      h.time_samples_auto = true;
      h.time_samples = 0;
    } else {
      h.time_samples = r.integer(key, in_range_int(3, 65536));
      if (!h.harmonics_auto && h.time_samples < 2 * h.harmonics + 1)
        r.violates(key, n, "time_samples >= 2*harmonics+1 (= " + std::to_string(2 * h.harmonics + 1) + ")");
    }
  }
  h.jacobian = r.string("hbm.jacobian", {"analytic", "finite_difference", "finite_difference_full"});
  h.tolerance = r.number("hbm.tolerance", [](double v) -> std::optional<std::string> {
    return v > 0 && v < 1 ? std::nullopt : std::optional<std::string>("0 < tolerance < 1");
  });
  h.energy_tolerance = r.number("hbm.energy_tolerance", [](double v) -> std::optional<std::string> {
    return v > 0 && v <= 1 ? std::nullopt : std::optional<std::string>("0 < energy_tolerance <= 1");
  });
  h.auto_tolerance = r.number("hbm.auto_tolerance", [](double v) -> std::optional<std::string> {
    return v > 0 && v < 1 ? std::nullopt : std::optional<std::string>("0 < auto_tolerance < 1");
  });
  h.auto_max_harmonics = r.integer("hbm.auto_max_harmonics", in_range_int(1, 200));
  h.auto_max_time_samples = r.integer("hbm.auto_max_time_samples", in_range_int(16, 65536));

  auto& cn = c.continuation;
  cn.frequency_start_hz = r.number("continuation.frequency_start_hz", positive);
  cn.frequency_end_hz = r.number("continuation.frequency_end_hz", positive);
  if (cn.frequency_end_hz == cn.frequency_start_hz)
    r.violates("continuation.frequency_end_hz", r.node("continuation.frequency_end_hz"), "frequency_end_hz != frequency_start_hz");
  {
    const std::string key = "continuation.initial_step";
    const toml::node& n = r.node(key);
    if (auto v = n.as_string()) {
      if (v->get() != "auto") r.violates(key, n, "a number > 0 (Hz-equivalent) or \"auto\"");
      cn.initial_step = 0.0;  // auto
    } else {
      cn.initial_step = r.number(key, positive);
    }
  }
  cn.max_points = r.integer("continuation.max_points", in_range_int(1, 1'000'000));

  c.motion.x = r.motion("motion.x");
  c.motion.y = r.motion("motion.y");
  c.motion.z = r.motion("motion.z");

  {
    const std::string key = "study.vary";
    const toml::node& n = r.node(key);
    auto t = n.as_table();
    if (!t) r.fail(key, &n, key + ": expected a table { \"dotted.key\" = [values] }");
    for (const auto& [k, v] : *t) {
      const std::string vk(k.str());
      if (!find_key(vk) || vk.rfind("study.", 0) == 0) r.fail(key, &v, key + ": '" + vk + "' is not a case key that can vary" + suggestion(vk));
      auto a = v.as_array();
      if (!a || a->empty()) r.fail(key, &v, key + ": '" + vk + "' needs a non-empty array of values");
      std::vector<std::string> values;
      for (const auto& e : *a) {
        std::ostringstream s;
        if (auto str = e.as_string()) s << '"' << str->get() << '"';
        else if (auto fl = e.as_floating_point()) {
          char buf[32];  // shortest text that reads back to the same double
          const auto res = std::to_chars(buf, buf + sizeof buf, fl->get());
          std::string t(buf, res.ptr);
          if (t.find_first_of(".eEn") == std::string::npos) t += ".0";
          s << t;
        } else e.visit([&](auto&& x) {
          if constexpr (toml::is_array<decltype(x)>) s << toml::toml_formatter{x, toml::format_flags::none};
          else if constexpr (toml::is_table<decltype(x)>) s << "{}";
          else s << x;
        });
        values.push_back(s.str());
      }
      c.study.vary.emplace_back(vk, values);
    }
  }

  if (auto t = r.root()["expect"].as_table())
    for (const auto& [k, v] : *t) c.expect[std::string(k.str())] = v.value<double>().value_or(0.0);
}

}  // namespace

Case parse_case(const std::string& text, const fs::path& file, const std::vector<std::string>& overrides) {
  toml::table root;
  try {
    root = toml::parse(text, file.string());
  } catch (const toml::parse_error& e) {
    std::ostringstream s;
    s << file.string() << ":" << e.source().begin.line << ":" << e.source().begin.column
      << ": TOML syntax error: " << e.description();
    throw InputError(s.str());
  }
  Case c;
  c.file = fs::absolute(file).lexically_normal();
  c.directory = c.file.parent_path();

  // --set overrides: validated like file keys, reported as "--set key=value".
  std::map<std::string, std::string> overridden;
  for (const auto& o : overrides) {
    if (o.find_first_of("\n\r") != std::string::npos)
      throw InputError(file.string() + ": --set " + o.substr(0, o.find_first_of("\n\r")) +
                       "...: contains a line break; give one KEY=VALUE per --set");
    const auto [key, value] = split_override(o);
    if (!find_key(key) && key.rfind("expect.", 0) != 0)
      throw InputError(file.string() + ": --set " + o + ": unknown key '" + key + "'" + suggestion(key));
    toml::table holder;
    auto v = parse_value(holder, key, value);
    const auto dot = key.rfind('.');
    toml::table* target = &root;
    if (dot != std::string::npos) {
      const std::string section = key.substr(0, dot);
      if (!root.contains(section)) root.insert(section, toml::table{});
      target = root[section].as_table();
      if (!target) throw InputError(file.string() + ": --set " + o + ": [" + section + "] is not a table in the case file");
    }
    target->insert_or_assign(key.substr(dot == std::string::npos ? 0 : dot + 1), *v.node());
    overridden[key] = value;
  }

  Reader reader(root, c.file, overridden);
  find_unknown(root, "", reader);
  insert_defaults(root);
  read_all(reader, c);
  c.locations = reader.locations();

  std::ostringstream toml_text, json_text;
  toml_text << toml::toml_formatter{root};
  json_text << toml::json_formatter{root};
  c.resolved_toml = toml_text.str();
  c.resolved_json = json_text.str();
  return c;
}

mesh::SectorGeometry sector_geometry(const Case& c) {
  const auto& g = c.geometry;
  mesh::SectorGeometry s;
  s.sectors = c.structure.sectors;
  s.hub_radius = g.hub_radius;
  s.disk_outer_radius = g.disk_outer_radius;
  s.disk_thickness = g.disk_thickness;
  s.blade_length = g.blade_length;
  s.blade_chord = g.blade_chord;
  s.blade_thickness = g.blade_thickness;
  s.blade_twist_deg = g.blade_twist_deg;
  s.shroud_thickness = g.shroud_thickness;
  s.shroud_width = g.shroud_width;
  s.shroud_contact_angle_deg = g.shroud_contact_angle_deg;
  s.element_order = g.element_order;
  s.mesh_size = g.mesh_size;
  return s;
}

Case load_case(const fs::path& file, const std::vector<std::string>& overrides) {
  if (!fs::exists(file)) throw InputError(file.string() + ": case file does not exist");
  if (fs::is_directory(file)) throw InputError(file.string() + ": is a folder, not a case file");
  // Only regular files of a case file's size (a device or a pipe would be read forever).
  constexpr std::uintmax_t kMaxCaseBytes = 16u << 20;
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) throw InputError(file.string() + ": not a regular file, not a case file");
  if (fs::file_size(file, ec) > kMaxCaseBytes || ec)
    throw InputError(file.string() + ": larger than 16 MiB (or unreadable): not a case file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot read the case file");
  std::ostringstream s;
  s << in.rdbuf();
  return parse_case(s.str(), file, overrides);
}

std::string default_case_text() {
  std::ostringstream s;
  s << "# shroudsim case file: every key at its default.\n"
       "# Units: SI (m, kg, s, N, Pa), angles in degrees, frequencies in Hz, speeds in rpm.\n"
       "# Paths are relative to this file. Unknown keys are errors.\n";
  for (const auto& [section, doc] : case_sections()) {
    if (section == "expect") continue;
    bool header = false;
    for (const auto& spec : case_schema()) {
      const auto dot = spec.key.rfind('.');
      const std::string sec = dot == std::string::npos ? "" : spec.key.substr(0, dot);
      if (sec != section) continue;
      if (!header && !section.empty()) s << "\n[" << section << "]  # " << doc << "\n";
      header = true;
      const std::string name = spec.key.substr(dot == std::string::npos ? 0 : dot + 1);
      std::string line = name + " = " + spec.default_toml;
      if (line.size() < 40) line.resize(40, ' ');
      s << line << " # " << spec.doc << "; " << spec.range << "\n";
    }
  }
  return s.str();
}

}  // namespace shroudsim::io
