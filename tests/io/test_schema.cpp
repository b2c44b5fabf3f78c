// The case schema (io/schema.hpp) is the one source of the keys: io::Case's defaults, the
// rules' texts, the generated docs (docs/case_keys.md) and the libraries' own defaults where
// a library option means the same as a case key.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "continuation/arclength.hpp"
#include "core/error.hpp"
#include "forced/frequency_response.hpp"
#include "forced/shooting.hpp"
#include "frf/sector.hpp"
#include "frf/static_shroud.hpp"
#include "io/case.hpp"
#include "io/schema.hpp"

namespace shroudsim::io {
namespace {

std::string read_text(const std::string& relative) {
  std::ifstream in(std::string(SHROUDSIM_SOURCE_DIR) + "/" + relative);
  EXPECT_TRUE(in.good()) << relative;
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(Schema, DefaultCaseHoldsTheSchemaDefaults) {
  const Case defaults;
  const Case empty = parse_case("", "case.toml");
  const Case printed = parse_case(default_case_text(), "defaults.toml");
  for (const auto& spec : case_schema()) {
    EXPECT_EQ(spec.value_toml(defaults), spec.default_toml) << spec.key;
    EXPECT_EQ(spec.value_toml(empty), spec.default_toml) << spec.key;
    EXPECT_EQ(spec.value_toml(printed), spec.default_toml) << spec.key;
  }
  // What value_toml does not show: the flags of the keys that take a word.
  EXPECT_TRUE(defaults.modal.all_harmonic_indices);
  EXPECT_FALSE(defaults.hbm.harmonics_auto);
  EXPECT_FALSE(defaults.hbm.time_samples_auto);
  EXPECT_FALSE(defaults.contact.normal_preload_static);
  EXPECT_EQ(defaults.structure.type, StructureType::sector);
  EXPECT_EQ(defaults.contact.model, contact::Model::full3d);
  EXPECT_TRUE(defaults.locations.empty());
}

TEST(Schema, EveryWordOfAChoiceReadsBackAsItself) {
  const std::string lumped = "[structure]\ntype = \"lumped\"\nsectors = 1\nmass = [[1.0]]\nstiffness = [[1.0]]\n";
  int choices = 0;
  for (const auto& spec : case_schema()) {
    if (spec.range.rfind("one of ", 0) != 0) continue;
    ++choices;
    const std::regex word("\"([^\"]*)\"");
    for (auto it = std::sregex_iterator(spec.range.begin(), spec.range.end(), word); it != std::sregex_iterator();
         ++it) {
      const std::string w = (*it)[1];
      const bool needs_lumped = (spec.key == "structure.type" && w == "lumped") ||
                                (spec.key == "response.stability_method" && w == "shooting");
      const Case c = parse_case(needs_lumped ? lumped : "", "case.toml", {spec.key + "=\"" + w + "\""});
      EXPECT_EQ(spec.value_toml(c), "\"" + w + "\"") << spec.key;
    }
  }
  // structure.type, modal.eigensolver, modal.shroud, contact.model, contact.discretization,
  // contact.tangential_update, hbm.jacobian, study.method, response.stability_method
  EXPECT_EQ(choices, 9);
}

TEST(Schema, MessagesQuoteTheDocumentedRule) {
  // The text a violation reports is the rule's text in the docs.
  for (const auto& [key, value] :
       std::vector<std::pair<std::string, std::string>>{{"material.poisson_ratio", "0.5"},
                                                        {"modal.damping_ratio", "1"},
                                                        {"geometry.blade_twist_deg", "61"},
                                                        {"geometry.disk_outer_radius", "0.05"},
                                                        {"geometry.blade_thickness", "0.06"},
                                                        {"continuation.frequency_end_hz", "100"},
                                                        {"hbm.energy_tolerance", "0"},
                                                        {"contact.normal_stiffness", "0"},
                                                        {"static.speed_rpm", "-1"},
                                                        {"modal.modes", "0"},
                                                        {"campbell.speed_rpm", "[10.0, 5.0]"},
                                                        {"campbell.engine_orders", "[0]"},
                                                        {"campbell.speed_points", "1"}}) {
    std::string message;
    try {
      parse_case("", "case.toml", {key + "=" + value});
    } catch (const InputError& e) {
      message = e.what();
    }
    const std::string head = " violates: ";
    const auto at = message.find(head);
    ASSERT_NE(at, std::string::npos) << key << ": " << message;
    EXPECT_NE(message.find(key + " = "), std::string::npos) << message;
    const std::string rule = message.substr(at + head.size());
    EXPECT_NE(find_key(key)->range.find(rule), std::string::npos)
        << key << ": '" << rule << "' not in '" << find_key(key)->range << "'";
  }
}

TEST(Schema, EveryKeyIsDocumented) {
  const std::string reference = read_text("docs/case_keys.md");
  std::set<std::string> keys;
  for (const auto& spec : case_schema()) {
    EXPECT_TRUE(keys.insert(spec.key).second) << "declared twice: " << spec.key;
    EXPECT_FALSE(spec.doc.empty()) << spec.key;
    EXPECT_FALSE(spec.type.empty()) << spec.key;
    EXPECT_FALSE(spec.default_toml.empty()) << spec.key;
    EXPECT_NE(reference.find("| `" + spec.key + "` |"), std::string::npos) << spec.key << " not in docs/case_keys.md";
  }
}

TEST(Schema, CommittedReferenceIsWhatTheCodeGenerates) {
  EXPECT_TRUE(read_text("docs/case_keys.md") == case_reference_markdown())
      << "docs/case_keys.md is out of date: build/src/app/shroudsim --print-case-reference > docs/case_keys.md";
}

/// The keys named in docs/contract.md's "Case file sections": `[section]` sets the section,
/// `key` (or `key = ...`) is a key of it, `a.b` a full key, `prefix_*` any key so named.
TEST(Schema, KeysOfTheContractAreDeclared) {
  const std::string contract = read_text("docs/contract.md");
  const auto begin = contract.find("## Case file sections");
  ASSERT_NE(begin, std::string::npos);
  const std::string text = contract.substr(begin, contract.find("\n## ", begin + 1) - begin);
  const std::set<std::string> commands = {"run", "mesh", "modes", "campbell", "frf", "contact", "static", "study"};
  std::set<std::string> sections;
  for (const auto& s : case_sections()) sections.insert(s.name);
  const std::regex code("`([^`]+)`");
  std::string section;
  int checked = 0;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), code); it != std::sregex_iterator(); ++it) {
    std::string token = (*it)[1];
    if (token.front() == '"') continue;  // a value
    if (token.rfind("[[", 0) == 0) {
      EXPECT_NE(find_key(token.substr(2, token.size() - 4)), nullptr) << token;
      ++checked;
      continue;
    }
    if (token.front() == '[') {
      section = token.substr(1, token.size() - 2);
      EXPECT_TRUE(sections.count(section)) << token;
      continue;
    }
    token = token.substr(0, token.find(' '));
    if (token.back() == '*') {
      const std::string prefix = section + "." + token.substr(0, token.size() - 1);
      EXPECT_TRUE(std::any_of(case_schema().begin(), case_schema().end(), [&](const KeySpec& k) {
        return k.key.rfind(prefix, 0) == 0;
      })) << token;
      ++checked;
      continue;
    }
    const std::string key = token.find('.') != std::string::npos || section.empty() ? token : section + "." + token;
    if (!find_key(key) && commands.count(token)) continue;  // "the shroud contact of `modes` and `campbell`"
    EXPECT_NE(find_key(key), nullptr) << key << " (docs/contract.md) is not declared";
    ++checked;
  }
  EXPECT_GT(checked, 40);
}

// Libraries keep defaults of their own (tests use them without a case file); where a library
// option means what a case key means, the two defaults agree.
TEST(Schema, LibraryDefaultsAgreeWithTheCaseDefaults) {
  const Case c;
  // mesh::SectorGeometry: every parameter is a [geometry] key (or structure.sectors).
  EXPECT_EQ(sector_geometry(c).fingerprint(), mesh::SectorGeometry{}.fingerprint());

  const contact::PairParameters pair;
  EXPECT_EQ(pair.tangential_stiffness, c.contact.tangential_stiffness);
  EXPECT_EQ(pair.normal_stiffness, c.contact.normal_stiffness);
  EXPECT_EQ(pair.friction_coefficient, c.contact.friction_coefficient);
  EXPECT_EQ(pair.normal_preload, c.contact.normal_preload);

  const hbm::ContactEvaluatorOptions evaluator;
  EXPECT_EQ(evaluator.law.model, c.contact.model);
  EXPECT_EQ(evaluator.law.update, c.contact.tangential_update);
  EXPECT_EQ(evaluator.n_harmonics, c.hbm.harmonics);
  EXPECT_EQ(evaluator.n_time_samples, c.hbm.time_samples);
  EXPECT_EQ(evaluator.jacobian, c.hbm.jacobian);

  const modal::ModalOptions modal;
  EXPECT_EQ(modal.modes, c.modal.modes);
  EXPECT_EQ(modal.method, c.modal.eigensolver);

  const forced::ShootingOptions shooting;
  EXPECT_EQ(shooting.min_steps_per_period, c.response.shooting_steps);

  const frf::SectorForcing forcing;  // (excitation node and force: no default, set by the caller)
  EXPECT_EQ(forcing.engine_order, c.excitation.engine_order);
  EXPECT_EQ(forcing.damping_ratio, c.modal.damping_ratio);
  EXPECT_EQ(forcing.residual_flexibility, c.modal.residual_flexibility);

  const forced::FrequencyResponseSettings response;
  EXPECT_EQ(response.frequency_start_hz, c.continuation.frequency_start_hz);
  EXPECT_EQ(response.frequency_end_hz, c.continuation.frequency_end_hz);
  EXPECT_EQ(response.initial_step_hz, c.continuation.initial_step);  // 0: "auto"
  EXPECT_EQ(response.max_points, c.continuation.max_points);
  EXPECT_EQ(response.tolerance, c.hbm.tolerance);

  // continuation::ArclengthOptions is generic (lambda in any unit, steps in scaled units):
  // only its point cap and Newton tolerance mean continuation.max_points and hbm.tolerance.
  // Its initial_step (0.5 scaled units) is not continuation.initial_step (Hz, or "auto").
  const continuation::ArclengthOptions arclength;
  EXPECT_EQ(arclength.max_points, c.continuation.max_points);
  EXPECT_EQ(arclength.tolerance, c.hbm.tolerance);

  // frf::StaticShroudSettings: its stiffnesses and friction coefficient default to 0 (not
  // usable: the caller always sets them, pipeline/modal_stage.cpp from contact.*); the rest agree.
  const frf::StaticShroudSettings settings;
  EXPECT_EQ(settings.increments, c.static_contact.increments);
  EXPECT_EQ(settings.interference, c.contact.interference);
  EXPECT_EQ(settings.frame_angle, c.contact.frame_angle_deg);
  EXPECT_EQ(settings.speed_rad_s, c.static_contact.speed_rpm);  // both 0: at rest
}

}  // namespace
}  // namespace shroudsim::io
