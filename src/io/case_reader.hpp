#pragma once
// Internal to shroudsim_io (it exposes toml++, a private dependency): typed reads of the
// values of a case document, every problem reported as InputError
//   "<file>:<line>:<column>: <key> = <value> violates: <rule>"   (violates)
//   "<file>:<line>:<column>: <key>: expected ..., got <type> <value>"  (a wrong type)
// or, for a key given with --set, "<file>: --set <key>=<value>: ..." in place of the
// position. case.cpp parses the document; schema.cpp reads each declared key through this.
#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "io/case.hpp"

namespace shroudsim::io {

/// A value as quoted in messages: strings in quotes, arrays in TOML, tables as {...};
/// at most 60 characters.
std::string value_text(const toml::node& node);
/// "a string", "an integer", "a number", ... for "expected X, got <type_name> <value>".
std::string type_name(const toml::node& node);
/// " (did you mean '<key>'?)" for the declared key nearest to `key`, or "".
std::string suggestion(const std::string& key);

class Reader {
 public:
  /// root: the document with every default inserted; overridden: key -> --set value text.
  Reader(toml::table& root, std::filesystem::path file, std::map<std::string, std::string> overridden);

  [[noreturn]] void fail(const std::string& key, const toml::node* node, const std::string& what) const;
  [[noreturn]] void violates(const std::string& key, const toml::node& node, const std::string& constraint) const;
  /// "<file>:<line>:<column>: " or "<file>: --set <key>=<value>: " or "<file>: ".
  std::string where(const std::string& key, const toml::node* node) const;

  /// The node of a key (every declared key has one: defaults are inserted); records where
  /// it came from (locations()).
  const toml::node& node(const std::string& key) const;
  const std::map<std::string, std::string>& locations() const { return locations_; }

  double number(const std::string& key) const;      ///< an integer or a float, finite
  long long integer(const std::string& key) const;  ///< an integer (any size)
  bool boolean(const std::string& key) const;
  std::string string(const std::string& key) const;
  /// The index in `words` of the key's string value; else violates: one of "a" | "b".
  std::size_t word(const std::string& key, const std::vector<std::string>& words) const;
  std::vector<double> numbers(const std::string& key, const toml::node& n) const;  ///< finite numbers
  std::vector<double> numbers(const std::string& key) const { return numbers(key, node(key)); }
  std::vector<int> integers(const std::string& key, const toml::node& n) const;  ///< each |value| <= 1e9
  std::vector<int> integers(const std::string& key) const { return integers(key, node(key)); }
  std::array<double, 3> vec3(const std::string& key) const;
  Eigen::MatrixXd matrix(const std::string& key) const;  ///< n rows of n numbers ([] : 0 x 0)
  std::vector<MotionHarmonic> motion(const std::string& key) const;

  const std::filesystem::path& file() const { return file_; }

 private:
  toml::table& root_;
  std::filesystem::path file_;
  std::map<std::string, std::string> overridden_;
  mutable std::map<std::string, std::string> locations_;
};

/// `one of "a" | "b" | ...`: the rule of a key that takes one of a few words.
std::string one_of_text(const std::vector<std::string>& words);

}  // namespace shroudsim::io
