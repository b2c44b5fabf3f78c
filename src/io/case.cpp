#include "io/case.hpp"

#include <toml++/toml.h>
#include <algorithm>
#include <fstream>
#include <map>
#include <sstream>

#include "core/error.hpp"
#include "io/case_reader.hpp"
#include "io/schema.hpp"

namespace shroudsim::io {
namespace {

namespace fs = std::filesystem;

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
    if (find_key(key)) continue;
    const bool is_section = prefix.empty() && std::any_of(case_sections().begin(), case_sections().end(),
                                                          [&](const SectionSpec& s) { return s.name == key; });
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

std::string section_of(const std::string& key) {
  const auto dot = key.rfind('.');
  return dot == std::string::npos ? "" : key.substr(0, dot);
}

/// Every key in file order, each section's rules over several keys after its keys.
void read_all(const Reader& r, Case& c) {
  for (const auto& section : case_sections()) {
    for (const auto& spec : case_schema())
      if (section_of(spec.key) == section.name) spec.read(r, c);
    if (section.check) section.check(r, c);
  }
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
    if (!find_key(key))
      throw InputError(file.string() + ": --set " + o + ": unknown key '" + key + "'" + suggestion(key));
    toml::table holder;
    auto v = parse_value(holder, key, value);
    const auto dot = key.rfind('.');
    toml::table* target = &root;
    if (dot != std::string::npos) {
      const std::string section = key.substr(0, dot);
      if (!root.contains(section)) root.insert(section, toml::table{});
      target = root[section].as_table();
      if (!target)
        throw InputError(file.string() + ": --set " + o + ": [" + section + "] is not a table in the case file");
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

std::string to_string(StructureType type) { return type == StructureType::lumped ? "lumped" : "sector"; }

std::string to_string(ModalShroud shroud) {
  switch (shroud) {
    case ModalShroud::open: return "open";
    case ModalShroud::stuck: return "stuck";
    case ModalShroud::contact: return "contact";
  }
  return "?";
}

std::string to_string(StabilityMethod method) {
  switch (method) {
    case StabilityMethod::automatic: return "auto";
    case StabilityMethod::hill: return "hill";
    case StabilityMethod::shooting: return "shooting";
  }
  return "?";
}

std::string default_case_text() {
  std::ostringstream s;
  s << "# shroudsim case file: every key at its default.\n"
       "# Units: SI (m, kg, s, N, Pa), angles in degrees, frequencies in Hz, speeds in rpm.\n"
       "# Paths are relative to this file. Unknown keys are errors.\n";
  for (const auto& section : case_sections()) {
    if (!section.name.empty()) s << "\n[" << section.name << "]  # " << section.doc << "\n";
    for (const auto& rule : section.rules) s << "# checked together: " << rule << "\n";
    for (const auto& spec : case_schema()) {
      if (section_of(spec.key) != section.name) continue;
      std::string line = spec.key.substr(section.name.size() + (section.name.empty() ? 0 : 1));
      line += " = " + spec.default_toml;
      if (line.size() < 40) line.resize(40, ' ');
      s << line << " # " << spec.doc << (spec.unit.empty() ? "" : " (" + spec.unit + ")")
        << (spec.range.empty() ? "" : "; " + spec.range) << "\n";
    }
  }
  return s.str();
}

}  // namespace shroudsim::io
