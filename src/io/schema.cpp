// The case-file schema: each key declared once, in file order (schema_builder.hpp says how
// a declaration becomes the reader, the default, the TOML text and the docs).
#include "io/schema.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>

#include "io/schema_builder.hpp"

namespace shroudsim::io {
namespace {

namespace fs = std::filesystem;
using schema::at;
using schema::End;
using schema::range_text;
using schema::toml_array;
using schema::toml_float;

bool lumped(const Case& c) { return c.structure.type == StructureType::lumped; }
int lumped_size(const Case& c) { return static_cast<int>(c.structure.mass.rows()); }
std::string size_text(const Case& c) { return std::to_string(lumped_size(c)) + " (the size of structure.mass)"; }

fs::path mesh_path(const Case& c, const std::string& text) {
  fs::path p(text);
  if (p.is_relative()) p = c.directory / p;
  return p.lexically_normal();
}

bool symmetric(const Eigen::MatrixXd& m) { return m.size() == 0 || (m - m.transpose()).norm() <= 1e-12 * m.norm(); }
/// The smallest eigenvalue of a symmetric matrix.
double smallest_eigenvalue(const Eigen::MatrixXd& m) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(m, Eigen::EigenvaluesOnly).eigenvalues().minCoeff();
}
/// No eigenvalue below 0 but for round-off of the largest (a negative eigenvalue is an energy
/// source, not a structure).
bool semidefinite(const Eigen::MatrixXd& m) {
  if (m.size() == 0) return true;
  const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(m, Eigen::EigenvaluesOnly).eigenvalues();
  return ev.minCoeff() >= -1e-12 * std::max(ev.cwiseAbs().maxCoeff(), 1e-300);
}

std::string matrix_toml(const Eigen::MatrixXd& m) {
  std::string s = "[";
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    std::vector<double> row(m.cols());
    for (Eigen::Index c = 0; c < m.cols(); ++c) row[static_cast<std::size_t>(c)] = m(r, c);
    s += (r ? ", " : "") + toml_array(row, toml_float);
  }
  return s + "]";
}

/// structure.mass, stiffness, damping: lumped only, n x n, symmetric.
schema::Key<Eigen::MatrixXd>& matrix(schema::Declarations& d, const std::string& key,
                                     Eigen::MatrixXd StructureSection::*member, const std::string& unit,
                                     const std::string& doc) {
  auto& k = d.other<Eigen::MatrixXd>(key, "matrix (n rows of n numbers)", Eigen::MatrixXd(), unit, doc);
  const auto m = at(&Case::structure, member);
  k.read_value = [](const Reader& r, const std::string& key, const Case&) { return r.matrix(key); };
  k.store = [m](Case& c, const Eigen::MatrixXd& v) { m.ref(c) = v; };
  k.load = [m](const Case& c) { return m.cref(c); };
  k.format = matrix_toml;
  return k;
}

/// Rules every lumped matrix has (after its own): [] unless lumped, symmetric.
void lumped_matrix_rules(schema::Key<Eigen::MatrixXd>& k, const std::string& key) {
  k.sentence(
      "[] unless structure.type = \"lumped\"",
      [](const Case& c, const Eigen::MatrixXd& v) { return lumped(c) || v.size() == 0; },
      [key](const Case&, const Eigen::MatrixXd&) { return key + " is only for structure.type = \"lumped\""; });
  k.rule(
      "lumped: symmetric", [](const Case& c, const Eigen::MatrixXd& v) { return !lumped(c) || symmetric(v); },
      [](const Case&, const Eigen::MatrixXd&) { return std::string("a symmetric matrix"); });
}

std::vector<ContactElement> read_contact_elements(const Reader& r, const std::string& key, const Case& c) {
  const toml::node& n = r.node(key);
  auto a = n.as_array();
  if (!a) r.fail(key, &n, key + ": expected an array of tables ([[contact.elements]])");
  static const std::vector<std::pair<std::string, int ContactElement::*>> dof_keys = {
      {"x_dof", &ContactElement::x_dof},
      {"y_dof", &ContactElement::y_dof},
      {"z_dof", &ContactElement::z_dof},
      {"other_x_dof", &ContactElement::other_x_dof},
      {"other_y_dof", &ContactElement::other_y_dof},
      {"other_z_dof", &ContactElement::other_z_dof}};
  static const std::vector<std::pair<std::string, std::optional<double> ContactElement::*>> value_keys = {
      {"friction_coefficient", &ContactElement::friction_coefficient},
      {"normal_stiffness", &ContactElement::normal_stiffness},
      {"tangential_stiffness", &ContactElement::tangential_stiffness},
      {"normal_preload", &ContactElement::normal_preload},
      {"frame_angle_deg", &ContactElement::frame_angle_deg}};
  std::vector<ContactElement> out;
  for (const auto& e : *a) {
    auto t = e.as_table();
    if (!t) r.fail(key, &e, key + ": expected tables ([[contact.elements]])");
    ContactElement el;
    for (const auto& [k, v] : *t) {
      const std::string name(k.str());
      const std::string full = key + "." + name;
      auto is = [&](const auto& entry) { return entry.first == name; };
      if (auto dk = std::find_if(dof_keys.begin(), dof_keys.end(), is); dk != dof_keys.end()) {
        auto i = v.as_integer();
        if (!i) r.fail(full, &v, full + ": expected an integer DOF index, got " + type_name(v));
        if (i->get() < 0 || i->get() > 1'000'000) r.violates(full, v, "0 <= dof");
        el.*(dk->second) = static_cast<int>(i->get());
      } else if (auto vk = std::find_if(value_keys.begin(), value_keys.end(), is); vk != value_keys.end()) {
        double d = 0;
        if (auto i = v.as_integer()) d = static_cast<double>(i->get());
        else if (auto f = v.as_floating_point()) d = f->get();
        else r.fail(full, &v, full + ": expected a number, got " + type_name(v));
        if (!std::isfinite(d)) r.violates(full, v, "a finite number");
        // The rules of the [contact] key it overrides.
        if (auto why = find_key("contact." + name)->check_number(c, d)) r.violates(full, v, *why);
        el.*(vk->second) = d;
      } else {
        r.fail(full, &v,
               "unknown key '" + full +
                   "' (contact elements take x_dof, y_dof, z_dof, other_x_dof, "
                   "other_y_dof, other_z_dof, friction_coefficient, normal_stiffness, tangential_stiffness, "
                   "normal_preload, frame_angle_deg)");
      }
    }
    if (el.x_dof < 0 && el.y_dof < 0 && el.z_dof < 0)
      r.fail(key, &e, key + ": an element needs at least one of x_dof, y_dof, z_dof");
    out.push_back(el);
  }
  return out;
}

std::string contact_elements_toml(const std::vector<ContactElement>& elements) {
  return toml_array(elements, [](const ContactElement& e) {
    std::string s;
    auto add = [&](const std::string& name, const std::string& value) {
      s += (s.empty() ? "" : ", ") + name + " = " + value;
    };
    for (auto [name, d] : {std::pair{"x_dof", e.x_dof},
                           {"y_dof", e.y_dof},
                           {"z_dof", e.z_dof},
                           {"other_x_dof", e.other_x_dof},
                           {"other_y_dof", e.other_y_dof},
                           {"other_z_dof", e.other_z_dof}})
      if (d >= 0) add(name, std::to_string(d));
    for (auto [name, v] : {std::pair{"friction_coefficient", e.friction_coefficient},
                           {"normal_stiffness", e.normal_stiffness},
                           {"tangential_stiffness", e.tangential_stiffness},
                           {"normal_preload", e.normal_preload},
                           {"frame_angle_deg", e.frame_angle_deg}})
      if (v) add(name, toml_float(*v));
    return "{ " + s + " }";
  });
}

using Vary = std::vector<std::pair<std::string, std::vector<std::string>>>;

Vary read_vary(const Reader& r, const std::string& key, const Case&) {
  const toml::node& n = r.node(key);
  auto t = n.as_table();
  if (!t) r.fail(key, &n, key + ": expected a table { \"dotted.key\" = [values] }");
  Vary out;
  for (const auto& [k, v] : *t) {
    const std::string vk(k.str());
    if (!find_key(vk) || vk.rfind("study.", 0) == 0)
      r.fail(key, &v, key + ": '" + vk + "' is not a case key that can vary" + suggestion(vk));
    auto a = v.as_array();
    if (!a || a->empty()) r.fail(key, &v, key + ": '" + vk + "' needs a non-empty array of values");
    std::vector<std::string> values;
    for (const auto& e : *a) {
      std::ostringstream s;
      if (auto str = e.as_string()) s << '"' << str->get() << '"';
      else if (auto fl = e.as_floating_point()) {
        std::string t = shortest(fl->get());
        if (t.find_first_of(".eEn") == std::string::npos) t += ".0";
        s << t;
      } else
        e.visit([&](auto&& x) {
          if constexpr (toml::is_array<decltype(x)>) s << toml::toml_formatter{x, toml::format_flags::none};
          else if constexpr (toml::is_table<decltype(x)>) s << "{}";
          else s << x;
        });
      values.push_back(s.str());
    }
    out.emplace_back(vk, values);
  }
  return out;
}

using Sample = std::vector<SampleInput>;

/// study.sample: { "dotted.key" = { distribution = "uniform", min = .., max = .. }, ... }.
Sample read_sample(const Reader& r, const std::string& key, const Case&) {
  const toml::node& n = r.node(key);
  auto t = n.as_table();
  if (!t) r.fail(key, &n, key + ": expected a table { \"dotted.key\" = { distribution = ..., ... } }");
  Sample out;
  for (const auto& [k, v] : *t) {
    const std::string vk(k.str());
    const KeySpec* spec = find_key(vk);
    if (!spec || vk.rfind("study.", 0) == 0)
      r.fail(key, &v, key + ": '" + vk + "' is not a case key that can be sampled" + suggestion(vk));
    if (spec->type != "number")
      r.fail(key, &v, key + ": '" + vk + "' is a " + spec->type + " key; only number keys can be sampled");
    auto d = v.as_table();
    if (!d) r.fail(key, &v, key + ": '" + vk + "' needs a table { distribution = \"uniform\", min = ..., max = ... }");
    SampleInput in;
    in.key = vk;
    auto dist = (*d)["distribution"].value<std::string>();
    if (!dist || (*dist != "uniform" && *dist != "normal" && *dist != "lognormal"))
      r.fail(key, &v, key + ": '" + vk + "': distribution must be one of \"uniform\" | \"normal\" | \"lognormal\"");
    in.distribution = *dist;
    const std::pair<const char*, const char*> names = *dist == "uniform"  ? std::pair{"min", "max"}
                                                      : *dist == "normal" ? std::pair{"mean", "std"}
                                                                          : std::pair{"median", "log_std"};
    for (const auto& [field, value] : *d) {
      const std::string f(field.str());
      if (f != "distribution" && f != names.first && f != names.second)
        r.fail(key, &value,
               key + ": '" + vk + "': unknown field '" + f + "' for a " + *dist + " distribution (it takes " +
                   names.first + " and " + names.second + ")");
    }
    auto field = [&](const char* name) {
      const toml::node* f = d->get(name);
      if (!f) r.fail(key, &v, key + ": '" + vk + "': a " + *dist + " distribution needs " + name);
      std::optional<double> x = f->value<double>();
      if (!x || !std::isfinite(*x))
        r.fail(key, f, key + ": '" + vk + "': " + name + " must be a finite number, got " + value_text(*f));
      return *x;
    };
    in.a = field(names.first);
    in.b = field(names.second);
    if (*dist == "uniform" && !(in.a < in.b)) r.fail(key, &v, key + ": '" + vk + "': needs min < max");
    if (*dist != "uniform" && !(in.b > 0)) r.fail(key, &v, key + ": '" + vk + "': needs " + names.second + " > 0");
    if (*dist == "lognormal" && !(in.a > 0)) r.fail(key, &v, key + ": '" + vk + "': needs median > 0");
    out.push_back(in);
  }
  return out;
}

std::string sample_toml(const Sample& sample) {
  std::string s;
  for (const auto& in : sample) {
    const bool uni = in.distribution == "uniform", nor = in.distribution == "normal";
    s += (s.empty() ? "" : ", ") + schema::quoted(in.key) + " = { distribution = " + schema::quoted(in.distribution) +
         ", " +
         (uni   ? "min"
          : nor ? "mean"
                : "median") +
         " = " + toml_float(in.a) + ", " +
         (uni   ? "max"
          : nor ? "std"
                : "log_std") +
         " = " + toml_float(in.b) + " }";
  }
  return s.empty() ? "{}" : "{ " + s + " }";
}

std::string vary_toml(const Vary& vary) {
  std::string s;
  for (const auto& [key, values] : vary)
    s += (s.empty() ? "" : ", ") + schema::quoted(key) + " = " +
         toml_array(values, [](const std::string& v) { return v; });
  return s.empty() ? "{}" : "{ " + s + " }";
}

schema::Key<std::vector<MotionHarmonic>>& motion(schema::Declarations& d, const std::string& key,
                                                 std::vector<MotionHarmonic> MotionSection::*member,
                                                 std::vector<MotionHarmonic> def, const std::string& doc) {
  auto& k = d.other<std::vector<MotionHarmonic>>(key, "rows [harmonic, cosine, sine]", std::move(def), "m", doc);
  const auto m = at(&Case::motion, member);
  k.read_value = [](const Reader& r, const std::string& key, const Case&) { return r.motion(key); };
  k.store = [m](Case& c, const std::vector<MotionHarmonic>& v) { m.ref(c) = v; };
  k.load = [m](const Case& c) { return m.cref(c); };
  k.format = [](const std::vector<MotionHarmonic>& v) {
    return toml_array(v, [](const MotionHarmonic& h) {
      std::string row = "[";  // (one += at a time: GCC 12 warns falsely about "[" + std::string)
      row += std::to_string(h.harmonic) + ", " + toml_float(h.cosine) + ", " + toml_float(h.sine) + "]";
      return row;
    });
  };
  k.form = "harmonic an integer in 0..10000";
  return k;
}

/// hbm.harmonics, hbm.time_samples: also "auto" (the flag set, the value 0: the search picks it).
void auto_word(schema::Key<long long>& k, int HbmSection::*value, bool HbmSection::*flag, std::string violation) {
  k.store = [=](Case& c, const long long& v) {
    c.hbm.*value = static_cast<int>(v);
    c.hbm.*flag = false;
  };
  k.or_word({"auto", std::move(violation),
             [=](Case& c) {
               c.hbm.*flag = true;
               c.hbm.*value = 0;
             },
             [=](const Case& c) { return c.hbm.*flag; }});
}

struct Schema {
  std::vector<KeySpec> keys;
  std::vector<SectionSpec> sections;
};

Schema declare() {
  schema::Declarations d;
  using G = GeometrySection;
  using C = ContactSection;
  using H = HbmSection;

  d.section("", "");
  d.text("name", at(&Case::name), "shrouded_blade",
         "result folder name (results/<name>) and mesh name (meshes/<name>.msh)")
      .rule("non-empty, only letters, digits, _ - .", [](const Case&, const std::string& v) {
        return !v.empty() && v != "." && v != ".." &&
               v.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-.") ==
                   std::string::npos;
      });

  d.section("structure", "what is analysed: an FE sector of a bladed disk, or a small lumped model");
  d.choice("structure.type", at(&Case::structure, &StructureSection::type), StructureType::sector,
           {StructureType::sector, StructureType::lumped}, to_string, "FE sector (default) or lumped M, K, C matrices");
  d.integer("structure.sectors", at(&Case::structure, &StructureSection::sectors), 8, "",
            "Nb, number of sectors of the wheel")
      .rule(
          range_text(2, 1000) + " (lumped: " + range_text(1, 1000) + ")",
          [](const Case& c, const long long& v) { return v >= (lumped(c) ? 1 : 2) && v <= 1000; },
          [](const Case& c, const long long&) { return range_text(lumped(c) ? 1 : 2, 1000); });
  {
    auto& k = d.other<std::string>("structure.mesh", "string (path)", "", "",
                                   "a .msh sector mesh with groups hub, cyclic_low/high, shroud_low/high, relative to "
                                   "the case file; \"\" = generate from [geometry]");
    k.read_value = [](const Reader& r, const std::string& key, const Case&) { return r.string(key); };
    k.store = [](Case& c, const std::string& v) { c.structure.mesh = v.empty() ? fs::path() : mesh_path(c, v); };
    k.load = [](const Case& c) { return c.structure.mesh.string(); };
    k.format = schema::quoted;
    k.rule(
        "\"\" or an existing mesh file",
        [](const Case& c, const std::string& v) { return v.empty() || fs::exists(mesh_path(c, v)); },
        [](const Case& c, const std::string& v) {
          return "an existing mesh file (looked for " + mesh_path(c, v).string() + ")";
        });
  }
  {
    auto& k = matrix(d, "structure.mass", &StructureSection::mass, "kg", "lumped mass matrix");
    k.sentence(
        "lumped: required", [](const Case& c, const Eigen::MatrixXd& v) { return !lumped(c) || v.rows() > 0; },
        [](const Case&, const Eigen::MatrixXd&) {
          return std::string("structure.mass is required when structure.type = \"lumped\"");
        });
    lumped_matrix_rules(k, "structure.mass");
    k.rule(
        "lumped: positive definite",
        [](const Case& c, const Eigen::MatrixXd& v) {
          return !lumped(c) || Eigen::LLT<Eigen::MatrixXd>(v).info() == Eigen::Success;
        },
        [](const Case&, const Eigen::MatrixXd&) { return std::string("positive definite"); });
  }
  for (const auto& [name, member, unit, doc] :
       {std::tuple{"structure.stiffness", &StructureSection::stiffness, "N/m", "lumped stiffness matrix"},
        std::tuple{"structure.damping", &StructureSection::damping, "N s/m", "lumped viscous damping matrix"}}) {
    const std::string key = name;
    auto& k = matrix(d, key, member, unit, doc);
    const bool damping = key == "structure.damping";
    if (damping)
      k.rule(
          "lumped: [] or the size of structure.mass",
          [](const Case& c, const Eigen::MatrixXd& v) {
            return !lumped(c) || v.rows() == 0 || v.rows() == lumped_size(c);
          },
          [](const Case&, const Eigen::MatrixXd&) { return std::string("[] or the size of structure.mass"); });
    else
      k.rule(
          "lumped: the size of structure.mass",
          [](const Case& c, const Eigen::MatrixXd& v) { return !lumped(c) || v.rows() == lumped_size(c); },
          [](const Case& c, const Eigen::MatrixXd&) {
            const std::string n = std::to_string(lumped_size(c));
            return "the same size as structure.mass (" + n + " x " + n + ")";
          });
    lumped_matrix_rules(k, key);
    k.rule(
        "lumped: positive semidefinite",
        [](const Case& c, const Eigen::MatrixXd& v) { return !lumped(c) || semidefinite(v); },
        [](const Case&, const Eigen::MatrixXd& v) {
          return "positive semidefinite (its smallest eigenvalue is " + std::to_string(smallest_eigenvalue(v)) + ")";
        });
  }

  d.section("geometry",
            "built-in shrouded blade sector generator (metres, degrees); used when structure.mesh is empty");
  auto& hub =
      d.number("geometry.hub_radius", at(&Case::geometry, &G::hub_radius), 0.10, "m", "bore radius, clamped").above(0);
  d.number("geometry.disk_outer_radius", at(&Case::geometry, &G::disk_outer_radius), 0.16, "m",
           "disk rim radius where the blade stands")
      .above(0)
      .compare(">", hub);
  d.number("geometry.disk_thickness", at(&Case::geometry, &G::disk_thickness), 0.03, "m", "axial thickness of the disk")
      .above(0);
  d.number("geometry.blade_length", at(&Case::geometry, &G::blade_length), 0.25, "m",
           "radial length of the blade from rim to shroud")
      .above(0);
  auto& chord =
      d.number("geometry.blade_chord", at(&Case::geometry, &G::blade_chord), 0.05, "m", "blade chord").above(0);
  d.number("geometry.blade_thickness", at(&Case::geometry, &G::blade_thickness), 0.006, "m", "blade thickness")
      .above(0)
      .compare("<", chord);
  d.number("geometry.blade_twist_deg", at(&Case::geometry, &G::blade_twist_deg), 20.0, "deg",
           "blade twist from root to tip")
      .within(-60, End::closed, 60, End::closed);
  d.number("geometry.shroud_thickness", at(&Case::geometry, &G::shroud_thickness), 0.006, "m",
           "radial thickness of the tip shroud")
      .above(0);
  d.number("geometry.shroud_width", at(&Case::geometry, &G::shroud_width), 0.05, "m", "axial width of the tip shroud")
      .above(0);
  d.number("geometry.shroud_contact_angle_deg", at(&Case::geometry, &G::shroud_contact_angle_deg), 45.0, "deg",
           "contact face angle to the radial plane")
      .within(0, End::closed, 90, End::open);
  d.integer("geometry.element_order", at(&Case::geometry, &G::element_order), 2, "",
            "1 = 4-node, 2 = 10-node tetrahedra")
      .range(1, 2);
  d.number("geometry.mesh_size", at(&Case::geometry, &G::mesh_size), 0.01, "m", "target element size").above(0);
  d.number(
       "geometry.max_elements", at(&Case::geometry, &G::max_elements), 1.0e6, "",
       "largest estimated element count meshed (volume / (0.04 mesh_size^3), which overestimates gmsh's count by up "
       "to 2x); a finer mesh_size is refused before meshing unless this is raised")
      .above(0);
  d.section_rule(
      "a generated sector (structure.type = \"sector\", no structure.mesh): the keys fit together "
      "(mesh::SectorGeometry::validate): sectors >= 3; the blade section within 90% of the pitch at the "
      "rim; shroud_width above the axial extent of the twisted blade tip; the contact faces do not cross "
      "(shroud_width/2 * tan(shroud_contact_angle_deg) < 0.8 * half the pitch at the shroud); mesh_size "
      "<= the smallest feature and >= 1e-4 * the outer radius",
      [](const Case& c) -> std::optional<std::pair<std::string, std::string>> {
        if (lumped(c) || !c.structure.mesh.empty()) return std::nullopt;
        const auto v = sector_geometry(c).validate();
        if (v.empty()) return std::nullopt;
        return v.front();
      });

  d.section("material", "isotropic linear elastic material (SI)");
  d.number("material.youngs_modulus", at(&Case::material, &MaterialSection::youngs_modulus), 210e9, "Pa",
           "Young's modulus")
      .above(0);
  d.number("material.poisson_ratio", at(&Case::material, &MaterialSection::poisson_ratio), 0.3, "", "Poisson's ratio")
      .within(-1, End::open, 0.5, End::open);
  d.number("material.density", at(&Case::material, &MaterialSection::density), 7850.0, "kg/m^3", "density").above(0);

  d.section("modal", "cyclic-symmetry modal analysis");
  d.integer("modal.modes", at(&Case::modal, &ModalSection::modes), 50, "", "modes kept per harmonic index")
      .range(1, 2000);
  {
    auto& k = d.integers("modal.harmonic_indices", at(&Case::modal, &ModalSection::harmonic_indices), {},
                         "harmonic indices of the nodal diameter map (listed in any order; repeats count once)");
    k.store = [](Case& c, const std::vector<int>& v) {
      c.modal.all_harmonic_indices = false;
      c.modal.harmonic_indices = v;
      std::sort(c.modal.harmonic_indices.begin(), c.modal.harmonic_indices.end());
      c.modal.harmonic_indices.erase(std::unique(c.modal.harmonic_indices.begin(), c.modal.harmonic_indices.end()),
                                     c.modal.harmonic_indices.end());
    };
    k.rule(
        "non-empty", [](const Case&, const std::vector<int>& v) { return !v.empty(); },
        [](const Case&, const std::vector<int>&) { return std::string("a non-empty list (or \"all\")"); });
    k.rule(
        "0 <= h < structure.sectors",
        [](const Case& c, const std::vector<int>& v) {
          return std::all_of(v.begin(), v.end(), [&](int h) { return h >= 0 && h < c.structure.sectors; });
        },
        [](const Case& c, const std::vector<int>&) {
          return "0 <= h < structure.sectors (" + std::to_string(c.structure.sectors) + ")";
        });
    k.or_word({"all", "\"all\" or a list of harmonic indices",
               [](Case& c) {
                 c.modal.all_harmonic_indices = true;
                 c.modal.harmonic_indices.clear();
               },
               [](const Case& c) { return c.modal.all_harmonic_indices; }},
              true);
  }
  d.number("modal.damping_ratio", at(&Case::modal, &ModalSection::damping_ratio), 0.001, "",
           "modal damping ratio of every mode")
      .within(0, End::closed, 1, End::open);
  d.boolean("modal.residual_flexibility", at(&Case::modal, &ModalSection::residual_flexibility), true,
            "add the static flexibility of the truncated modes");
  d.choice("modal.eigensolver", at(&Case::modal, &ModalSection::eigensolver), modal::EigenMethod::Block,
           {modal::EigenMethod::Block, modal::EigenMethod::Spectra}, modal::to_string,
           "block Krylov-Schur (default, faster) or Spectra's Lanczos (2n embedding for complex h)");
  d.choice(
      "modal.shroud", at(&Case::modal, &ModalSection::shroud), ModalShroud::open,
      {ModalShroud::open, ModalShroud::stuck, ModalShroud::contact}, to_string,
      "shroud contact of `modes` and `campbell`: open (blades coupled through the disk only), stuck (every matched "
      "shroud pair tied by contact.normal_stiffness and tangential_stiffness, shared by tributary area, in its "
      "contact frame) or contact (the pairs the static shroud contact closes, with contact.interference, tied; at "
      "each speed of a Campbell diagram with rotating effects); the forced response always starts from the open "
      "sector");

  d.section("campbell", "Campbell diagram");
  d.numbers("campbell.speed_rpm", at(&Case::campbell, &CampbellSection::speed_rpm), {0.0, 15000.0}, "rpm",
            "speed range")
      .rule("[min, max] with 0 <= min < max",
            [](const Case&, const std::vector<double>& v) { return v.size() == 2 && v[0] >= 0 && v[1] > v[0]; });
  d.integer("campbell.speed_points", at(&Case::campbell, &CampbellSection::speed_points), 31, "", "speeds in the range")
      .range(2, 10000);
  d.integers("campbell.engine_orders", at(&Case::campbell, &CampbellSection::engine_orders), {1, 2, 3, 4, 5, 6},
             "engine-order lines drawn and crossed")
      .rule("engine orders >= 1", [](const Case&, const std::vector<int>& v) {
        return std::all_of(v.begin(), v.end(), [](int e) { return e >= 1; });
      });
  d.boolean("campbell.rotating_effects", at(&Case::campbell, &CampbellSection::rotating_effects), false,
            "centrifugal stiffening and spin softening");

  d.section("static",
            "only for `shroudsim static`: the shroud contact of the spinning sector (interference, friction)");
  d.number("static.speed_rpm", at(&Case::static_contact, &StaticSection::speed_rpm), 0.0, "rpm",
           "rotor speed of the static shroud contact")
      .at_least(0);
  d.integer("static.increments", at(&Case::static_contact, &StaticSection::increments), 10, "",
            "equal steps of speed^2 from rest to static.speed_rpm (the friction state is carried from step to step)")
      .range(1, 1000);

  d.section("excitation", "travelling-wave excitation");
  d.integer("excitation.engine_order", at(&Case::excitation, &ExcitationSection::engine_order), 1, "",
            "engine order m: harmonic n lives in harmonic index n*m mod Nb")
      .range(0, 100000);
  d.vec3("excitation.point", at(&Case::excitation, &ExcitationSection::point), {0.0, 0.35, 0.0}, "m",
         "sector: the force acts at the nearest node");
  {
    auto& k = d.vec3("excitation.force", at(&Case::excitation, &ExcitationSection::force), {1.0, 1.0, 1.0}, "N",
                     "force amplitude (global x y z); lumped: one number");
    k.read_value = [](const Reader& r, const std::string& key, const Case& c) -> std::array<double, 3> {
      const toml::node& n = r.node(key);
      if (!n.is_number()) return r.vec3(key);
      if (!lumped(c)) r.violates(key, n, "3 numbers [Fx, Fy, Fz] for a sector (one number is for lumped models)");
      return {r.number(key), 0.0, 0.0};
    };
  }
  d.integer("excitation.dof", at(&Case::excitation, &ExcitationSection::dof), 0, "", "lumped: the excited DOF")
      .range(0, 1'000'000)
      .rule(
          "lumped: dof < the size of structure.mass",
          [](const Case& c, const long long& v) { return !lumped(c) || v < lumped_size(c); },
          [](const Case& c, const long long&) { return "dof < " + size_text(c); });
  d.number("excitation.speed_rpm", at(&Case::excitation, &ExcitationSection::speed_rpm), 0.0, "rpm",
           "rotor speed of the forced response; > 0 uses the modes with centrifugal stiffening and spin softening at "
           "that speed")
      .at_least(0);

  d.section("response", "where the response amplitude is reported");
  d.vec3("response.point", at(&Case::response, &ResponseSection::point), {0.0, 0.34, 0.0}, "m",
         "sector: the response is read at the nearest node");
  d.integer("response.dof", at(&Case::response, &ResponseSection::dof), 0, "", "lumped: the response DOF")
      .range(0, 1'000'000)
      .rule(
          "lumped: dof < the size of structure.mass",
          [](const Case& c, const long long& v) { return !lumped(c) || v < lumped_size(c); },
          [](const Case& c, const long long&) { return "dof < " + size_text(c); });
  d.boolean("response.shapes", at(&Case::response, &ResponseSection::shapes), true,
            "frf: write the operating deflection shapes (sector: frf.vtu, frf.pvd) and contact maps (contact_map.csv, "
            "sector: contact.vtu) at every resonance peak and at response.shapes_at_hz");
  d.boolean("response.stability", at(&Case::response, &ResponseSection::stability), true,
            "frf: the local stability of every point, by response.stability_method (frf.csv column `stable`, run.json "
            "frf.stability with the changes of stability: folds, period doublings, Neimark-Sacker points)");
  d.choice("response.stability_method", at(&Case::response, &ResponseSection::stability_method),
           StabilityMethod::automatic, {StabilityMethod::automatic, StabilityMethod::hill, StabilityMethod::shooting},
           to_string,
           "frf: how the points are judged (docs/physics.md section 9): hill = Hill's method (any model; with "
           "friction the slider is a state of the eigenproblem, whose size then grows by N per tangential direction "
           "and pair; on an FE sector the modes of every harmonic index 0..Nb/2 are computed for its perturbation "
           "families); shooting = Floquet multipliers of the time integration's period map (lumped models); auto = "
           "shooting for a lumped model with friction, hill for other lumped models, none for an FE sector (run.json "
           "says why)")
      .rule("shooting: a lumped structure (the FE sector has no time integration)",
            [](const Case& c, const StabilityMethod& v) { return v != StabilityMethod::shooting || lumped(c); });
  d.integer("response.shooting_steps", at(&Case::response, &ResponseSection::shooting_steps), 4096, "",
            "shooting: least time steps per excitation period (more where the stuck contact's highest mode needs "
            "them); the verdicts' error and cost against it: docs/physics.md section 9")
      .range(256, 65536);
  d.number("response.shooting_work", at(&Case::response, &ResponseSection::shooting_work), 1e8, "state-steps",
           "shooting: work bound of one curve, counted as the most its points could take (a state-step: one state "
           "of the time integration advanced one step): a curve that could need more is judged at every k-th point, "
           "the smallest k within the bound (run.json frf.stability.work, stride)")
      .within(1e5, End::closed, 1e12, End::closed);
  d.integer("response.stability_samples", at(&Case::response, &ResponseSection::stability_samples), 0, "",
            "hill with friction: time samples of the slider state (damper positions per pair and tangential "
            "direction), at most hbm.time_samples; auto = hbm.time_samples for a lumped model; for an FE sector "
            "hbm.time_samples where the damper positions fit within 800, else the most that fit (the default "
            "sector: 80 of 512); at lambda = 0 the problem is the "
            "harmonic balance's linearization at any count; the verdicts' error against it: docs/physics.md section 9")
      .range(3, 65536)
      .or_word({"auto", "\"auto\" or an integer >= 3", [](Case& c) { c.response.stability_samples = 0; },
                [](const Case& c) { return c.response.stability_samples == 0; }},
               true);
  d.numbers("response.shapes_at_hz", at(&Case::response, &ResponseSection::shapes_at_hz), {}, "Hz",
            "frf: further frequencies of shapes and contact maps (one per crossing of the curve)")
      .rule("every frequency > 0 and finite", [](const Case&, const std::vector<double>& v) {
        return std::all_of(v.begin(), v.end(), [](double f) { return f > 0.0 && std::isfinite(f); });
      });

  d.section("contact", "shroud friction contact");
  d.choice("contact.model", at(&Case::contact, &C::model), contact::Model::full3d,
           {contact::Model::full3d, contact::Model::quasi3d, contact::Model::one_d, contact::Model::one_d_exact},
           contact::to_string, "friction contact model");
  d.integer("contact.pairs", at(&Case::contact, &C::pairs), 0, "",
            "contact elements on the shroud face: the face split into this many patches (seeds spread evenly, each "
            "node to its nearest seed)")
      .range(1, 1'000'000)
      .or_word({"all", "\"all\" or a count >= 1", [](Case& c) { c.contact.pairs = 0; },
                [](const Case& c) { return c.contact.pairs == 0; }},
               true);
  d.choice("contact.discretization", at(&Case::contact, &C::discretization), frf::ContactDiscretization::patches,
           {frf::ContactDiscretization::patches, frf::ContactDiscretization::nodes}, frf::to_string,
           "sector: patches = each element acts on its patch's area-weighted mean relative displacement (converges "
           "under mesh refinement); nodes = on the patch's seed node pair alone (the paper's model)");
  d.number("contact.friction_coefficient", at(&Case::contact, &C::friction_coefficient), 0.3, "",
           "Coulomb friction coefficient mu")
      .at_least(0);
  d.number("contact.normal_stiffness", at(&Case::contact, &C::normal_stiffness), 1.0e6, "N/m",
           "normal contact stiffness per interface, shared over pairs by tributary area")
      .above(0);
  d.number("contact.tangential_stiffness", at(&Case::contact, &C::tangential_stiffness), 1.0e6, "N/m",
           "tangential contact stiffness per interface")
      .above(0);
  {
    auto& k =
        d.number("contact.normal_preload", at(&Case::contact, &C::normal_preload), 0.25, "N",
                 "normal preload per interface; < 0 means an initial gap -N0/kn; \"static\": each contact patch's "
                 "normal load (or gap) from the static shroud contact at excitation.speed_rpm "
                 "(contact.interference, `shroudsim static`)");
    k.store = [](Case& c, const double& v) {
      c.contact.normal_preload = v;
      c.contact.normal_preload_static = false;
    };
    k.or_word({"static",
               "a number (N) or \"static\"",
               [](Case& c) {
                 c.contact.normal_preload_static = true;
                 c.contact.normal_preload = 0.0;
               },
               [](const Case& c) { return c.contact.normal_preload_static; },
               {{"sector only", [](const Case& c, const std::string&) { return !lumped(c); },
                 [](const Case&, const std::string&) {
                   return std::string("a number (N): \"static\" needs an FE sector");
                 }}}});
  }
  d.number("contact.interference", at(&Case::contact, &C::interference), 0.0, "m",
           "sector: overlap of the shroud faces at rest, uniform over the face, for the static shroud contact "
           "(`static`); < 0: a gap");
  d.number("contact.frame_angle_deg", at(&Case::contact, &C::frame_angle_deg), 0.0, "deg",
           "turns the tangential axes t1, t2 about the normal");
  d.choice("contact.tangential_update", at(&Case::contact, &C::tangential_update),
           contact::TangentialUpdate::exact_linear,
           {contact::TangentialUpdate::exact_linear, contact::TangentialUpdate::radial_return}, contact::to_string,
           "time integration of the coupled tangential law");
  {
    auto& k = d.other<std::vector<ContactElement>>(
        "contact.elements", "array of tables", {}, "",
        "lumped contact elements: x_dof, y_dof, z_dof (at least one), other_x_dof, other_y_dof, other_z_dof (absent: "
        "ground), and per-element friction_coefficient, normal_stiffness, tangential_stiffness, normal_preload, "
        "frame_angle_deg (checked as the [contact] keys)");
    k.read_value = read_contact_elements;
    k.store = [](Case& c, const std::vector<ContactElement>& v) { c.contact.elements = v; };
    k.load = [](const Case& c) { return c.contact.elements; };
    k.format = contact_elements_toml;
    k.sentence(
        "[] unless structure.type = \"lumped\"",
        [](const Case& c, const std::vector<ContactElement>& v) { return lumped(c) || v.empty(); },
        [](const Case&, const std::vector<ContactElement>&) {
          return std::string("contact.elements is only for structure.type = \"lumped\"");
        });
    k.rule(
        "lumped: DOF indices < the size of structure.mass",
        [](const Case& c, const std::vector<ContactElement>& v) {
          return !lumped(c) || std::all_of(v.begin(), v.end(), [&](const ContactElement& e) {
            return std::max({e.x_dof, e.y_dof, e.z_dof, e.other_x_dof, e.other_y_dof, e.other_z_dof}) < lumped_size(c);
          });
        },
        [](const Case& c, const std::vector<ContactElement>&) { return "DOF indices < " + size_text(c); });
  }

  d.section("hbm", "multiharmonic balance with the alternating frequency-time scheme");
  auto_word(d.integer("hbm.harmonics", at(&Case::hbm, &H::harmonics), 5, "", "H: harmonics 0..H").range(1, 200),
            &H::harmonics, &H::harmonics_auto, "an integer 1 <= H <= 200 or \"auto\"");
  auto_word(
      d.integer("hbm.time_samples", at(&Case::hbm, &H::time_samples), 512, "", "N: time samples per period")
          .range(3, 65536)
          .rule(
              "time_samples >= 2*harmonics+1",
              [](const Case& c, const long long& v) { return c.hbm.harmonics_auto || v >= 2 * c.hbm.harmonics + 1; },
              [](const Case& c, const long long&) {
                return "time_samples >= 2*harmonics+1 (= " + std::to_string(2 * c.hbm.harmonics + 1) + ")";
              }),
      &H::time_samples, &H::time_samples_auto, "an integer N >= 2H+1 or \"auto\"");
  d.choice("hbm.jacobian", at(&Case::hbm, &H::jacobian), hbm::JacobianMethod::analytic,
           {hbm::JacobianMethod::analytic, hbm::JacobianMethod::finite_difference,
            hbm::JacobianMethod::finite_difference_full},
           hbm::to_string,
           "Jacobian of the contact forces (finite_difference: per pair; _full: the whole force vector, for comparison "
           "only)");
  d.number("hbm.tolerance", at(&Case::hbm, &H::tolerance), 1e-8, "", "Newton tolerance on the scaled residual")
      .within(0, End::open, 1, End::open);
  d.number("hbm.energy_tolerance", at(&Case::hbm, &H::energy_tolerance), 0.001, "",
           "largest energy-balance error (|excitation work - dissipation| per cycle, relative) of a point before the "
           "run counts as failed numerics (exit 3)")
      .within(0, End::open, 1, End::closed);
  d.number("hbm.auto_tolerance", at(&Case::hbm, &H::auto_tolerance), 0.01, "",
           "\"auto\" H or N: stop when the peak amplitude changes by less (relative)")
      .within(0, End::open, 1, End::open);
  d.integer("hbm.auto_max_harmonics", at(&Case::hbm, &H::auto_max_harmonics), 25, "",
            "\"auto\" harmonics: largest H tried")
      .range(1, 200);
  d.integer("hbm.auto_max_time_samples", at(&Case::hbm, &H::auto_max_time_samples), 4096, "",
            "\"auto\" time samples: largest N tried")
      .range(16, 65536);
  d.boolean("hbm.raise_time_samples", at(&Case::hbm, &H::raise_time_samples), true,
            "a fixed N whose forced response stops at a corner of the sampled law, finds no start or fails its energy "
            "check is traced again with 4 N, then 16 N (up to hbm.auto_max_time_samples); run.json frf.time_samples "
            "is the N of the result");

  d.section("continuation", "pseudo-arclength continuation over the excitation frequency");
  auto& start = d.number("continuation.frequency_start_hz",
                         at(&Case::continuation, &ContinuationSection::frequency_start_hz), 100.0, "Hz",
                         "start of the frequency range")
                    .above(0);
  d.number("continuation.frequency_end_hz", at(&Case::continuation, &ContinuationSection::frequency_end_hz), 220.0,
           "Hz", "end of the frequency range")
      .above(0)
      .compare("!=", start);
  d.number("continuation.initial_step", at(&Case::continuation, &ContinuationSection::initial_step), 0.0, "Hz",
           "initial arclength step: \"auto\" (1/400 of the range) or Hz-equivalent; never above 1/200 of the range")
      .above(0)
      .or_word({"auto", "a number > 0 (Hz-equivalent) or \"auto\"", [](Case& c) { c.continuation.initial_step = 0.0; },
                [](const Case& c) { return c.continuation.initial_step == 0.0; }},
               true);
  d.integer("continuation.max_points", at(&Case::continuation, &ContinuationSection::max_points), 5000, "",
            "maximum number of solution points")
      .range(1, 1'000'000);

  d.section("nlmodes",
            "only for `shroudsim nlmodes` (lumped models and FE sectors): the nonlinear mode by the extended periodic "
            "motion concept");
  auto& a_start = d.number("nlmodes.amplitude_start", at(&Case::nlmodes, &NlmodesSection::amplitude_start), 1e-6,
                           "m kg^0.5",
                           "smallest modal amplitude a (the fundamental's q_1^H M q_1 = a^2): where the contacts "
                           "still stick (a contact open at rest carries no force there: start above its closing)")
                      .above(0);
  d.number("nlmodes.amplitude_end", at(&Case::nlmodes, &NlmodesSection::amplitude_end), 1e-2, "m kg^0.5",
           "largest modal amplitude: into gross slip")
      .above(0)
      .compare(">", a_start);
  d.integer("nlmodes.mode", at(&Case::nlmodes, &NlmodesSection::mode), 1, "",
            "the linear mode (1-based, by ascending frequency, contacts linearized at rest) the nonlinear mode starts "
            "from")
      .range(1, 1'000'000);
  d.integer("nlmodes.max_points", at(&Case::nlmodes, &NlmodesSection::max_points), 500, "",
            "maximum number of points (the step is at most 0.05 decades of amplitude)")
      .range(2, 1'000'000);
  d.numbers("nlmodes.synthesis_scales", at(&Case::nlmodes, &NlmodesSection::synthesis_scales), {0.5, 1.0, 2.0}, "",
            "excitation levels (multiples of the case's excitation) of the forced responses synthesized from the "
            "mode (nlmodes_synthesis.csv)")
      .rule("every scale > 0 and finite", [](const Case&, const std::vector<double>& v) {
        return std::all_of(v.begin(), v.end(), [](double f) { return f > 0.0 && std::isfinite(f); });
      });
  d.boolean("nlmodes.compare_hb", at(&Case::nlmodes, &NlmodesSection::compare_hb), false,
            "also trace the full harmonic-balance forced response at every synthesis scale over the "
            "[continuation] range and compare its largest peak with the synthesized one "
            "(nlmodes_compare.csv, run.json nlmodes.comparison)");

  d.section("motion", "only for `shroudsim contact`: prescribed relative motion, rows [harmonic, cosine, sine] in m");
  motion(d, "motion.x", &MotionSection::x, {{1, 1e-5, 0.0}}, "relative tangential motion x(t)");
  motion(d, "motion.y", &MotionSection::y, {}, "relative tangential motion y(t)");
  motion(d, "motion.z", &MotionSection::z, {}, "relative normal motion z(t), > 0 presses");

  d.section("study", "only for `shroudsim study`: parameter sweeps");
  {
    auto& k = d.other<Vary>("study.vary", "table { \"dotted.key\" = [values] }", {}, "",
                            "each key's values (any case key but study.*); the points are the Cartesian product");
    k.read_value = read_vary;
    k.store = [](Case& c, const Vary& v) { c.study.vary = v; };
    k.load = [](const Case& c) { return c.study.vary; };
    k.format = vary_toml;
  }
  {
    auto& k = d.other<Sample>("study.sample", "table { \"dotted.key\" = { distribution, ... } }", {}, "",
                              "sampled study: each uncertain number key's distribution, { distribution = \"uniform\", "
                              "min, max }, { distribution = \"normal\", mean, std } or { distribution = "
                              "\"lognormal\", median, log_std }; the points are study.samples draws (not with "
                              "study.vary)");
    k.read_value = read_sample;
    k.store = [](Case& c, const Sample& v) { c.study.sample = v; };
    k.load = [](const Case& c) { return c.study.sample; };
    k.format = sample_toml;
  }
  d.integer("study.samples", at(&Case::study, &StudySection::samples), 100, "",
            "sampled study: how many points are drawn")
      .range(1, 10'000);
  d.choice("study.method", at(&Case::study, &StudySection::method), SampleMethod::latin_hypercube,
           {SampleMethod::random, SampleMethod::latin_hypercube, SampleMethod::sobol}, to_string,
           "sampled study: random (independent draws), latin_hypercube (one point in each of study.samples strata of "
           "every input) or sobol (the Sobol sequence, study.seed points in)");
  d.integer("study.seed", at(&Case::study, &StudySection::seed), 1, "",
            "sampled study: seed of the random draws (sobol: how many points of the sequence are skipped)")
      .range(0, 1'000'000'000);
  d.number("study.threshold_m", at(&Case::study, &StudySection::threshold_m), 0.0, "m",
           "sampled study: the peak amplitude whose exceedance probability is reported (0: none)")
      .at_least(0);
  d.section_rule("study.vary and study.sample are not both given (a sweep or a sampled study)",
                 [](const Case& c) -> std::optional<std::pair<std::string, std::string>> {
                   if (!c.study.vary.empty() && !c.study.sample.empty())
                     return std::pair<std::string, std::string>{"study.sample", "not both study.vary and study.sample"};
                   return std::nullopt;
                 });
  return {d.keys(), d.sections()};
}

const Schema& the_schema() {
  static const Schema s = declare();
  return s;
}

}  // namespace

const std::vector<KeySpec>& case_schema() { return the_schema().keys; }

const std::vector<SectionSpec>& case_sections() { return the_schema().sections; }

const KeySpec* find_key(const std::string& key) {
  const auto& s = case_schema();
  auto it = std::find_if(s.begin(), s.end(), [&](const KeySpec& k) { return k.key == key; });
  return it == s.end() ? nullptr : &*it;
}

namespace {

/// A Markdown table cell: '|' escaped, and '<' before a letter (no HTML tag: "results/<name>");
/// empty as "-". code: inside a code span (only '|' escaped).
std::string cell(const std::string& text, bool code = false) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const bool tag = !code && text[i] == '<' && i + 1 < text.size() &&
                     std::isalpha(static_cast<unsigned char>(text[i + 1]));
    out += text[i] == '|' || tag ? std::string("\\") + text[i] : std::string(1, text[i]);
  }
  return out.empty() ? "-" : out;
}

}  // namespace

std::string case_reference_markdown() {
  std::ostringstream s;
  s << "# Case file keys\n\n"
       "<!-- Generated by `shroudsim --print-case-reference > docs/case_keys.md` from src/io/schema.cpp; do not\n"
       "     edit: tests/io/test_schema.cpp fails when this file differs from what the code generates. -->\n\n"
       "Every key of a case file: its type, its default, its unit, what its value may be (the rules\n"
       "the case reader checks, in the order it checks them) and what it means. A value that breaks\n"
       "a rule stops the run with exit status 2 and one message naming the place and the rule,\n"
       "`<file>:<line>:<column>: <key> = <value> violates: <rule>` (`<file>: --set <key>=<value>: ...`\n"
       "for a key given with `--set`). Units: SI, angles in degrees, frequencies in Hz, speeds in rpm.\n"
       "Paths are relative to the case file. Unknown keys are errors. `shroudsim --print-defaults`\n"
       "prints a case file with every key at its default; [contract.md](contract.md) lists the\n"
       "commands and the result files.\n";
  for (const auto& section : case_sections()) {
    s << "\n## " << (section.name.empty() ? "Top level" : "[" + section.name + "]") << "\n\n";
    if (!section.doc.empty()) s << cell(section.doc) << ".\n\n";
    s << "| key | type | default | unit | allowed | meaning |\n| --- | --- | --- | --- | --- | --- |\n";
    for (const auto& spec : case_schema()) {
      const auto dot = spec.key.rfind('.');
      if ((dot == std::string::npos ? "" : spec.key.substr(0, dot)) != section.name) continue;
      s << "| `" << spec.key << "` | " << cell(spec.type) << " | `" << cell(spec.default_toml, true) << "` | "
        << cell(spec.unit) << " | " << cell(spec.range) << " | " << cell(spec.doc) << " |\n";
    }
    for (const auto& rule : section.rules) s << "\nChecked after the section's keys: " << cell(rule) << ".\n";
  }
  return s.str();
}

Case::Case() {
  for (const auto& k : case_schema()) k.set_default(*this);
}

}  // namespace shroudsim::io
