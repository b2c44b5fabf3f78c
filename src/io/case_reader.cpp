#include "io/case_reader.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/error.hpp"
#include "io/schema.hpp"

namespace shroudsim::io {
namespace {

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

}  // namespace

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
      if (name.size() >= 3 && spec.key.rfind(section, 0) == 0 &&
          spec.key.find(name, section.size()) != std::string::npos) {
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

std::string one_of_text(const std::vector<std::string>& words) {
  std::string list;
  for (const auto& w : words) list += (list.empty() ? "" : " | ") + ("\"" + w + "\"");
  return "one of " + list;
}

Reader::Reader(toml::table& root, std::filesystem::path file, std::map<std::string, std::string> overridden)
    : root_(root), file_(std::move(file)), overridden_(std::move(overridden)) {}

void Reader::fail(const std::string& key, const toml::node* node, const std::string& what) const {
  throw InputError(where(key, node) + what);
}

void Reader::violates(const std::string& key, const toml::node& node, const std::string& constraint) const {
  fail(key, &node, key + " = " + value_text(node) + " violates: " + constraint);
}

std::string Reader::where(const std::string& key, const toml::node* node) const {
  auto it = overridden_.find(key);
  if (it != overridden_.end()) return file_.string() + ": --set " + key + "=" + it->second + ": ";
  if (node && node->source().begin.line > 0)
    return file_.string() + ":" + std::to_string(node->source().begin.line) + ":" +
           std::to_string(node->source().begin.column) + ": ";
  return file_.string() + ": ";
}

const toml::node& Reader::node(const std::string& key) const {
  const toml::node* n = root_.at_path(key).node();
  SHROUDSIM_CHECK(n != nullptr, "schema key with a default: " + key);
  std::string w = where(key, n);
  locations_[key] = w.substr(0, w.size() - 2);  // without the trailing ": "
  return *n;
}

double Reader::number(const std::string& key) const {
  const toml::node& n = node(key);
  double v = 0.0;
  if (auto i = n.as_integer()) v = static_cast<double>(i->get());
  else if (auto f = n.as_floating_point()) v = f->get();
  else fail(key, &n, key + ": expected a number, got " + type_name(n) + " " + value_text(n));
  if (!std::isfinite(v)) violates(key, n, "a finite number");
  return v;
}

long long Reader::integer(const std::string& key) const {
  const toml::node& n = node(key);
  auto i = n.as_integer();
  if (!i) fail(key, &n, key + ": expected an integer, got " + type_name(n) + " " + value_text(n));
  return i->get();
}

bool Reader::boolean(const std::string& key) const {
  const toml::node& n = node(key);
  auto b = n.as_boolean();
  if (!b) fail(key, &n, key + ": expected true or false, got " + type_name(n) + " " + value_text(n));
  return b->get();
}

std::string Reader::string(const std::string& key) const {
  const toml::node& n = node(key);
  auto s = n.as_string();
  if (!s) fail(key, &n, key + ": expected a string, got " + type_name(n) + " " + value_text(n));
  return s->get();
}

std::size_t Reader::word(const std::string& key, const std::vector<std::string>& words) const {
  const std::string s = string(key);
  const auto it = std::find(words.begin(), words.end(), s);
  if (it == words.end()) violates(key, node(key), one_of_text(words));
  return static_cast<std::size_t>(it - words.begin());
}

std::vector<double> Reader::numbers(const std::string& key, const toml::node& n) const {
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

std::vector<int> Reader::integers(const std::string& key, const toml::node& n) const {
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

std::array<double, 3> Reader::vec3(const std::string& key) const {
  const auto v = numbers(key);
  if (v.size() != 3) violates(key, node(key), "exactly 3 numbers [x, y, z]");
  return {v[0], v[1], v[2]};
}

Eigen::MatrixXd Reader::matrix(const std::string& key) const {
  const toml::node& n = node(key);
  auto a = n.as_array();
  if (!a) fail(key, &n, key + ": expected an array of rows, got " + type_name(n));
  const int rows = static_cast<int>(a->size());
  Eigen::MatrixXd m(rows, rows);
  for (int r = 0; r < rows; ++r) {
    const auto row = numbers(key, (*a)[static_cast<std::size_t>(r)]);
    if (static_cast<int>(row.size()) != rows)
      violates(key, (*a)[static_cast<std::size_t>(r)], "a square matrix (n rows of n numbers)");
    for (int c = 0; c < rows; ++c) m(r, c) = row[static_cast<std::size_t>(c)];
  }
  return m;
}

std::vector<MotionHarmonic> Reader::motion(const std::string& key) const {
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

}  // namespace shroudsim::io
