#pragma once
// Internal to shroudsim_io: how schema.cpp declares a key. A Key<V> holds the key's name,
// type, default, unit and meaning, how its value V is read from the document and stored in
// the Case member it fills, and its rules; spec() turns it into the KeySpec whose reader,
// default, TOML text and documented rules all come from this one declaration.
//
// A rule is a test with its text; the text is what a violation reports
// ("<key> = <value> violates: <text>") and what the docs list. Bounds generate their text
// ("> 0", "-1 < poisson_ratio < 0.5", "1 <= value <= 200"), comparisons with another key
// theirs ("disk_outer_radius > hub_radius"); other rules give it.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "core/format.hpp"
#include "io/case.hpp"
#include "io/case_reader.hpp"
#include "io/schema.hpp"

namespace shroudsim::io::schema {

/// Shortest text that reads back to v ("0.5", "-1", "1e-8", "2.1e11").
inline std::string number_text(double v) {
  std::string t = shortest(v);
  const auto e = t.find('e');
  if (e != std::string::npos) {  // "1e-08" -> "1e-8", "2.1e+11" -> "2.1e11"
    std::string exp = t.substr(e + 1);
    const bool negative = exp[0] == '-';
    if (exp[0] == '-' || exp[0] == '+') exp.erase(0, 1);
    exp.erase(0, std::min(exp.find_first_not_of('0'), exp.size() - 1));
    t = t.substr(0, e + 1) + (negative ? "-" : "") + exp;
  }
  return t;
}
/// A double as a TOML float ("0.1", "100.0", "1e-8").
inline std::string toml_float(double v) {
  std::string t = number_text(v);
  if (t.find_first_of(".eEni") == std::string::npos) t += ".0";
  return t;
}
inline std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char ch : s) out += ch == '"' || ch == '\\' ? std::string("\\") + ch : std::string(1, ch);
  return out + "\"";
}
/// "[a, b, c]" of the elements' texts.
template <class Container, class Format>
std::string toml_array(const Container& values, Format format) {
  std::string s = "[";
  for (const auto& v : values) s += (s.size() > 1 ? ", " : "") + format(v);
  return s + "]";
}

/// The text of an integer range: "lo <= value <= hi".
inline std::string range_text(long long lo, long long hi) {
  return std::to_string(lo) + " <= value <= " + std::to_string(hi);
}

/// The Case member a key fills.
template <class T>
struct Member {
  std::function<T&(Case&)> ref;
  std::function<const T&(const Case&)> cref;
};
template <class S, class T>
Member<T> at(S Case::*section, T S::*member) {
  return {[=](Case& c) -> T& { return (c.*section).*member; },
          [=](const Case& c) -> const T& { return (c.*section).*member; }};
}
template <class T>
Member<T> at(T Case::*member) {
  return {[=](Case& c) -> T& { return c.*member; }, [=](const Case& c) -> const T& { return c.*member; }};
}

/// A rule of a key's value v; the keys declared before v's are read into the Case.
template <class V>
struct Rule {
  std::string text;  ///< in the docs, and in the message unless `message`
  std::function<bool(const Case&, const V&)> holds;
  std::function<std::string(const Case&, const V&)> message = {};  ///< a message text with values
  bool sentence = false;  ///< the message is "<where>: <message>", not "<key> = <value> violates: <message>"
};

/// The key also takes one word (e.g. "auto") in place of a value.
struct Word {
  std::string word;
  std::string violation;           ///< the rule a string other than `word` violates
  std::function<void(Case&)> set;  ///< the Case for the word
  std::function<bool(const Case&)> is_set;
  std::vector<Rule<std::string>> rules = {};  ///< when the word may be given
};

enum class End { open, closed };

template <class V>
class Key {
 public:
  Key(std::string key, std::string type, V def, std::string unit, std::string doc)
      : key_(std::move(key)),
        type_(std::move(type)),
        def_(std::move(def)),
        unit_(std::move(unit)),
        doc_(std::move(doc)) {}

  std::string name() const { return key_.substr(key_.rfind('.') + 1); }

  // How V is read (the node's type and form), stored, loaded and written as TOML.
  std::function<V(const Reader&, const std::string&, const Case&)> read_value;
  std::function<void(Case&, const V&)> store;
  std::function<V(const Case&)> load;
  std::function<std::string(const V&)> format;
  std::string form;              ///< the rule the read itself checks (e.g. one of "a" | "b"), for the docs
  std::optional<Rule<V>> limit;  ///< checked after the rules, not documented (the C++ type's range)

  Key& rule(Rule<V> r) {
    rules_.push_back(std::move(r));
    return *this;
  }
  Key& rule(std::string text, std::function<bool(const Case&, const V&)> holds,
            std::function<std::string(const Case&, const V&)> message = {}) {
    return rule(Rule<V>{std::move(text), std::move(holds), std::move(message)});
  }
  /// A rule whose message is a sentence of its own ("structure.mass is required when ...").
  Key& sentence(std::string text, std::function<bool(const Case&, const V&)> holds,
                std::function<std::string(const Case&, const V&)> message) {
    return rule(Rule<V>{std::move(text), std::move(holds), std::move(message), true});
  }
  /// The key takes `w.word` too; default_word: that is its default.
  Key& or_word(Word w, bool default_word = false) {
    word_ = std::move(w);
    default_is_word_ = default_word;
    return *this;
  }

  // Bounds of a number: "> lo", ">= lo", "lo <= name < hi".
  Key& above(double lo) requires std::is_same_v<V, double> {
    return rule("> " + number_text(lo), [lo](const Case&, const double& v) { return v > lo; });
  }
  Key& at_least(double lo) requires std::is_same_v<V, double> {
    return rule(">= " + number_text(lo), [lo](const Case&, const double& v) { return v >= lo; });
  }
  Key& within(double lo, End lo_end, double hi, End hi_end) requires std::is_same_v<V, double> {
    return rule(number_text(lo) + (lo_end == End::closed ? " <= " : " < ") + name() +
                    (hi_end == End::closed ? " <= " : " < ") + number_text(hi),
                [=](const Case&, const double& v) {
                  return (lo_end == End::closed ? v >= lo : v > lo) && (hi_end == End::closed ? v <= hi : v < hi);
                });
  }
  /// "name op other" against a number key declared before: op one of ">", "<", "!=".
  Key& compare(const std::string& op, const Key<double>& other) requires std::is_same_v<V, double> {
    const auto other_value = other.load;
    return rule(name() + " " + op + " " + other.name(), [op, other_value](const Case& c, const double& v) {
      const double o = other_value(c);
      return op == ">" ? v > o : op == "<" ? v < o : v != o;
    });
  }
  // Bounds of an integer: "lo <= value <= hi".
  Key& range(long long lo, long long hi) requires std::is_same_v<V, long long> {
    return rule(range_text(lo, hi), [lo, hi](const Case&, const long long& v) { return v >= lo && v <= hi; });
  }

  KeySpec spec() const;

 private:
  template <class T>
  static void check(const Reader& r, const std::string& key, const Case& c, const Rule<T>& rule, const T& v) {
    if (rule.holds(c, v)) return;
    const std::string what = rule.message ? rule.message(c, v) : rule.text;
    if (rule.sentence) r.fail(key, &r.node(key), what);
    r.violates(key, r.node(key), what);
  }

  std::string key_, type_;
  V def_;
  std::string unit_, doc_;
  std::vector<Rule<V>> rules_;
  std::optional<Word> word_;
  bool default_is_word_ = false;
};

template <class V>
KeySpec Key<V>::spec() const {
  const auto self = std::make_shared<const Key<V>>(*this);
  KeySpec s;
  s.key = key_;
  s.type = type_;
  s.unit = unit_;
  s.doc = doc_;
  s.default_toml = default_is_word_ ? quoted(word_->word) : format(def_);
  std::vector<std::string> texts;
  if (!form.empty()) texts.push_back(form);
  for (const auto& r : rules_) texts.push_back(r.text);
  for (const auto& t : texts) s.range += (s.range.empty() ? "" : "; ") + t;
  if (word_) s.range += std::string(s.range.empty() ? "any" : "") + ", or " + quoted(word_->word);
  if (word_)
    for (const auto& r : word_->rules) s.range += " (" + r.text + ")";

  s.read = [self](const Reader& r, Case& c) {
    const std::string& key = self->key_;
    const toml::node& n = r.node(key);
    if (self->word_ && n.is_string()) {
      const std::string given = n.as_string()->get();
      if (given != self->word_->word) r.violates(key, n, self->word_->violation);
      for (const auto& rule : self->word_->rules) check(r, key, c, rule, given);
      self->word_->set(c);
      return;
    }
    const V v = self->read_value(r, key, c);
    for (const auto& rule : self->rules_) check(r, key, c, rule, v);
    if (self->limit) check(r, key, c, *self->limit, v);
    self->store(c, v);
  };
  s.set_default = [self](Case& c) {
    if (self->default_is_word_) self->word_->set(c);
    else self->store(c, self->def_);
  };
  s.value_toml = [self](const Case& c) {
    if (self->word_ && self->word_->is_set(c)) return quoted(self->word_->word);
    return self->format(self->load(c));
  };
  if constexpr (std::is_same_v<V, double>) {
    s.check_number = [self](const Case& c, double v) -> std::optional<std::string> {
      for (const auto& rule : self->rules_)
        if (!rule.holds(c, v)) return rule.message ? rule.message(c, v) : rule.text;
      return std::nullopt;
    };
  }
  return s;
}

/// Collects the declarations of schema.cpp, in file order.
class Declarations {
 public:
  /// Starts a section: the keys declared next belong to it.
  void section(std::string name, std::string doc) { sections_.push_back({std::move(name), std::move(doc), {}, {}}); }
  /// A rule over several keys of the current section, checked after its keys: `violation`
  /// gives (key, violated rule) of the first violation, or nullopt.
  void section_rule(std::string text,
                    std::function<std::optional<std::pair<std::string, std::string>>(const Case&)> violation) {
    SectionSpec& s = sections_.back();
    s.rules.push_back(text);
    auto before = s.check;
    s.check = [before, violation](const Reader& r, const Case& c) {
      if (before) before(r, c);
      if (auto v = violation(c)) r.violates(v->first, r.node(v->first), v->second);
    };
  }

  template <class V>
  Key<V>& add(std::shared_ptr<Key<V>> key) {
    Key<V>& k = *key;
    finish_.push_back([key] { return key->spec(); });
    return k;
  }

  /// A number (integer or float in the file), finite.
  Key<double>& number(std::string key, Member<double> m, double def, std::string unit, std::string doc) {
    auto k = std::make_shared<Key<double>>(std::move(key), "number", def, std::move(unit), std::move(doc));
    k->read_value = [](const Reader& r, const std::string& key, const Case&) { return r.number(key); };
    k->store = [m](Case& c, const double& v) { m.ref(c) = v; };
    k->load = [m](const Case& c) { return m.cref(c); };
    k->format = toml_float;
    return add(std::move(k));
  }
  /// An integer, stored as int (|value| <= 1e9, checked after the rules).
  Key<long long>& integer(std::string key, Member<int> m, int def, std::string unit, std::string doc) {
    auto k = std::make_shared<Key<long long>>(std::move(key), "integer", def, std::move(unit), std::move(doc));
    k->read_value = [](const Reader& r, const std::string& key, const Case&) { return r.integer(key); };
    k->store = [m](Case& c, const long long& v) { m.ref(c) = static_cast<int>(v); };
    k->load = [m](const Case& c) { return static_cast<long long>(m.cref(c)); };
    k->format = [](const long long& v) { return std::to_string(v); };
    k->limit = Rule<long long>{
        "|value| <= 1e9", [](const Case&, const long long& v) { return v >= -1'000'000'000 && v <= 1'000'000'000; }};
    return add(std::move(k));
  }
  Key<bool>& boolean(std::string key, Member<bool> m, bool def, std::string doc) {
    auto k = std::make_shared<Key<bool>>(std::move(key), "boolean", def, "", std::move(doc));
    k->read_value = [](const Reader& r, const std::string& key, const Case&) { return r.boolean(key); };
    k->store = [m](Case& c, const bool& v) { m.ref(c) = v; };
    k->load = [m](const Case& c) { return m.cref(c); };
    k->format = [](const bool& v) { return std::string(v ? "true" : "false"); };
    return add(std::move(k));
  }
  Key<std::string>& text(std::string key, Member<std::string> m, std::string def, std::string doc) {
    auto k = std::make_shared<Key<std::string>>(std::move(key), "string", std::move(def), "", std::move(doc));
    k->read_value = [](const Reader& r, const std::string& key, const Case&) { return r.string(key); };
    k->store = [m](Case& c, const std::string& v) { m.ref(c) = v; };
    k->load = [m](const Case& c) { return m.cref(c); };
    k->format = quoted;
    return add(std::move(k));
  }
  /// One of a few words, stored as the enum value whose name() is the word.
  template <class E>
  Key<E>& choice(std::string key, Member<E> m, E def, std::vector<E> values, std::string (*name)(E), std::string doc) {
    std::vector<std::string> words;
    for (E e : values) words.push_back(name(e));
    auto k = std::make_shared<Key<E>>(std::move(key), "string", def, "", std::move(doc));
    k->read_value = [values, words](const Reader& r, const std::string& key, const Case&) {
      return values[r.word(key, words)];
    };
    k->store = [m](Case& c, const E& v) { m.ref(c) = v; };
    k->load = [m](const Case& c) { return m.cref(c); };
    k->format = [name](const E& v) { return quoted(name(v)); };
    k->form = one_of_text(words);
    return add(std::move(k));
  }
  /// [x, y, z]: exactly 3 finite numbers.
  Key<std::array<double, 3>>& vec3(std::string key, Member<std::array<double, 3>> m, std::array<double, 3> def,
                                   std::string unit, std::string doc) {
    auto k =
        std::make_shared<Key<std::array<double, 3>>>(std::move(key), "[x, y, z]", def, std::move(unit), std::move(doc));
    k->read_value = [](const Reader& r, const std::string& key, const Case&) { return r.vec3(key); };
    k->store = [m](Case& c, const std::array<double, 3>& v) { m.ref(c) = v; };
    k->load = [m](const Case& c) { return m.cref(c); };
    k->format = [](const std::array<double, 3>& v) { return toml_array(v, toml_float); };
    return add(std::move(k));
  }
  /// An array of finite numbers.
  Key<std::vector<double>>& numbers(std::string key, Member<std::vector<double>> m, std::vector<double> def,
                                    std::string unit, std::string doc) {
    auto k = std::make_shared<Key<std::vector<double>>>(std::move(key), "array of numbers", std::move(def),
                                                        std::move(unit), std::move(doc));
    k->read_value = [](const Reader& r, const std::string& key, const Case&) { return r.numbers(key); };
    k->store = [m](Case& c, const std::vector<double>& v) { m.ref(c) = v; };
    k->load = [m](const Case& c) { return m.cref(c); };
    k->format = [](const std::vector<double>& v) { return toml_array(v, toml_float); };
    return add(std::move(k));
  }
  /// An array of integers (each |value| <= 1e9).
  Key<std::vector<int>>& integers(std::string key, Member<std::vector<int>> m, std::vector<int> def, std::string doc) {
    auto k = std::make_shared<Key<std::vector<int>>>(std::move(key), "array of integers", std::move(def), "",
                                                     std::move(doc));
    k->read_value = [](const Reader& r, const std::string& key, const Case&) { return r.integers(key); };
    k->store = [m](Case& c, const std::vector<int>& v) { m.ref(c) = v; };
    k->load = [m](const Case& c) { return m.cref(c); };
    k->format = [](const std::vector<int>& v) { return toml_array(v, [](int i) { return std::to_string(i); }); };
    return add(std::move(k));
  }
  /// A value of another form: read_value, store, load and format are set by the caller.
  template <class V>
  Key<V>& other(std::string key, std::string type, V def, std::string unit, std::string doc) {
    return add(
        std::make_shared<Key<V>>(std::move(key), std::move(type), std::move(def), std::move(unit), std::move(doc)));
  }

  /// The keys (each key's spec once every rule is declared) and the sections.
  std::vector<KeySpec> keys() const {
    std::vector<KeySpec> out;
    for (const auto& f : finish_) out.push_back(f());
    return out;
  }
  const std::vector<SectionSpec>& sections() const { return sections_; }

 private:
  std::vector<std::function<KeySpec()>> finish_;
  std::vector<SectionSpec> sections_;
};

}  // namespace shroudsim::io::schema
