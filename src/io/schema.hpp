#pragma once
// The case-file schema: every key, its default (TOML text), its range and its meaning.
// One table serves the reader (defaults, unknown-key detection) and --print-defaults.
#include <string>
#include <vector>

namespace shroudsim::io {

struct KeySpec {
  std::string key;           ///< dotted path, e.g. "hbm.harmonics"
  std::string default_toml;  ///< the default as a TOML value; "" = no default (optional)
  std::string range;         ///< allowed values, for the docs
  std::string doc;           ///< one line: meaning and unit
};

/// Every key of the case file, in file order, grouped by section.
const std::vector<KeySpec>& case_schema();
/// The spec of `key`, or nullptr.
const KeySpec* find_key(const std::string& key);
/// Section descriptions, in file order (first: "" for top-level keys).
const std::vector<std::pair<std::string, std::string>>& case_sections();

}  // namespace shroudsim::io
