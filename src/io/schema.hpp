#pragma once
// The case-file schema: every key declared once (schema.cpp) with its type, default, unit,
// the rules its value must satisfy, its meaning and the io::Case member it fills. From that
// one declaration come
//  - the defaults of io::Case (its constructor) and of the document read (absent keys),
//  - the checks of the case reader and their messages ("<key> = <value> violates: <rule>",
//    the rule's text generated from the rule itself),
//  - `shroudsim --print-defaults` (default_case_text) and docs/case_keys.md
//    (case_reference_markdown, `shroudsim --print-case-reference`).
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace shroudsim::io {

struct Case;
class Reader;  // io/case_reader.hpp, internal to shroudsim_io

struct KeySpec {
  std::string key;           ///< dotted path, e.g. "hbm.harmonics"
  std::string type;          ///< value type, for the docs: "number", "integer", "[x, y, z]", ...
  std::string default_toml;  ///< the default as a TOML value
  std::string unit;          ///< "m", "N/m", "Hz", "deg", "rpm", ...; "" when none
  std::string range;         ///< what the value may be: the text of the key's rules, "; "-separated
  std::string doc;           ///< one line: what the key means
  /// Reads the key's value from the document (defaults inserted), checks its rules in order
  /// and stores it in the Case; throws InputError at the first violation. The keys declared
  /// before are read (rules across keys use them).
  std::function<void(const Reader&, Case&)> read;
  /// Stores the default in a Case.
  std::function<void(Case&)> set_default;
  /// The key's value in a Case as TOML text (default_toml for a default Case).
  std::function<std::string(const Case&)> value_toml;
  /// Number keys: the text of the first rule that v violates (the rest of the case as
  /// given), else nullopt. Empty for other keys. The per-element overrides of
  /// [[contact.elements]] are checked by the rules of their [contact] key.
  std::function<std::optional<std::string>(const Case&, double)> check_number;
};

struct SectionSpec {
  std::string name;  ///< "" for the top-level keys
  std::string doc;
  std::vector<std::string> rules;  ///< rules over several keys of the section, for the docs
  /// Checks those rules after the section's keys are read (empty: none); throws InputError.
  std::function<void(const Reader&, const Case&)> check;
};

/// Every key of the case file, in file order, grouped by section (case_sections() order).
const std::vector<KeySpec>& case_schema();
/// The spec of `key`, or nullptr.
const KeySpec* find_key(const std::string& key);
/// The sections, in file order (first: "" for the top-level keys).
const std::vector<SectionSpec>& case_sections();

/// docs/case_keys.md: every section and key with type, default, unit, rules and meaning.
std::string case_reference_markdown();

}  // namespace shroudsim::io
