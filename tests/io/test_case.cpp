// Case files: defaults, overrides, and one clear message per kind of bad input.
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "io/case.hpp"
#include "io/schema.hpp"

namespace shroudsim::io {
namespace {

/// The InputError message parse_case raises for `text` (fails the test if none).
std::string error_of(const std::string& text, const std::vector<std::string>& sets = {}) {
  try {
    parse_case(text, "case.toml", sets);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError for:\n" << text;
  return "";
}

TEST(Case, EmptyFileTakesEveryDefault) {
  const Case c = parse_case("", "case.toml");
  EXPECT_EQ(c.name, "shrouded_blade");
  EXPECT_EQ(c.structure.sectors, 8);
  EXPECT_EQ(c.hbm.harmonics, 5);
  EXPECT_EQ(c.hbm.time_samples, 512);
  EXPECT_DOUBLE_EQ(c.material.youngs_modulus, 210e9);
  EXPECT_TRUE(c.modal.all_harmonic_indices);
  EXPECT_EQ(c.contact.pairs, 0);
  ASSERT_EQ(c.motion.x.size(), 1u);
  EXPECT_DOUBLE_EQ(c.motion.x[0].cosine, 1e-5);
}

TEST(Case, PrintedDefaultsParseBackToTheDefaults) {
  const Case printed = parse_case(default_case_text(), "defaults.toml");
  const Case empty = parse_case("", "case.toml");
  EXPECT_EQ(printed.resolved_json, empty.resolved_json);
  // Every schema key appears in the printed file.
  const std::string text = default_case_text();
  for (const auto& spec : case_schema()) {
    const auto dot = spec.key.rfind('.');
    EXPECT_NE(text.find(spec.key.substr(dot == std::string::npos ? 0 : dot + 1) + " = "), std::string::npos)
        << spec.key;
  }
}

TEST(Case, OverridesApplyAndAreValidated) {
  const Case c = parse_case("[hbm]\nharmonics = 3\n", "case.toml",
                            {"hbm.harmonics=7", "contact.model=quasi3d", "modal.harmonic_indices=[0, 2, 2, 1]"});
  EXPECT_EQ(c.hbm.harmonics, 7);
  EXPECT_EQ(c.contact.model, contact::Model::quasi3d);
  EXPECT_EQ(c.modal.harmonic_indices, (std::vector<int>{0, 1, 2}));
  const std::string e = error_of("", {"hbm.harmonics=0"});
  EXPECT_NE(e.find("--set hbm.harmonics=0"), std::string::npos) << e;
  EXPECT_NE(e.find("violates: 1 <= value <= 200"), std::string::npos) << e;
  EXPECT_NE(error_of("", {"hbm.harmonic=7"}).find("unknown key 'hbm.harmonic' (did you mean 'hbm.harmonics'?)"),
            std::string::npos);
  EXPECT_NE(error_of("", {"hbm.harmonics"}).find("expected KEY=VALUE"), std::string::npos);
}

TEST(Case, ResolvedCaseHoldsOverridesAndDefaults) {
  const Case c = parse_case("name = \"a\"\n", "case.toml", {"contact.friction_coefficient=0.2"});
  EXPECT_NE(c.resolved_json.find("\"friction_coefficient\" : 0.2"), std::string::npos) << c.resolved_json;
  EXPECT_NE(c.resolved_toml.find("time_samples = 512"), std::string::npos);
}

struct BadCase {
  const char* what;
  std::string text;
  std::vector<std::string> expected;  ///< substrings of the message: location, key, constraint
};

class BadCases : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadCases, OneMessageNamingFileLineAndKey) {
  const std::string e = error_of(GetParam().text);
  for (const auto& part : GetParam().expected)
    EXPECT_NE(e.find(part), std::string::npos) << "'" << part << "' not in: " << e;
}

INSTANTIATE_TEST_SUITE_P(
    Case, BadCases,
    ::testing::Values(
        BadCase{"syntax", "name = \"x\"\n[hbm\nharmonics = 5\n", {"case.toml:2:", "TOML syntax error"}},
        BadCase{"unknown_key",
                "[hbm]\nharmonic = 5\n",
                {"case.toml:2:", "unknown key 'hbm.harmonic'", "did you mean 'hbm.harmonics'"}},
        BadCase{"unknown_section", "[hmb]\nharmonics = 5\n", {"case.toml:1:", "unknown key 'hmb'"}},
        BadCase{"wrong_type",
                "[material]\ndensity = \"heavy\"\n",
                {"case.toml:2:11", "material.density: expected a number, got a string \"heavy\""}},
        BadCase{"wrong_type_harmonics",
                "[hbm]\nharmonics = \"five\"\n",
                {"case.toml:2:13", "hbm.harmonics = \"five\" violates: an integer 1 <= H <= 200 or \"auto\""}},
        BadCase{"wrong_type_bool",
                "[modal]\nresidual_flexibility = 1\n",
                {"case.toml:2:", "modal.residual_flexibility: expected true or false"}},
        BadCase{"negative_modulus",
                "[material]\nyoungs_modulus = -1e9\n",
                {"case.toml:2:18", "material.youngs_modulus = -1", "violates: > 0"}},
        BadCase{"poisson_half",
                "[material]\npoisson_ratio = 0.5\n",
                {"case.toml:2:", "material.poisson_ratio = 0.5", "violates: -1 < poisson_ratio < 0.5"}},
        BadCase{"zero_sectors",
                "[structure]\nsectors = 0\n",
                {"case.toml:2:", "structure.sectors = 0", "violates: 2 <= value <= 1000"}},
        BadCase{"mesh_size_above_blade",
                "[geometry]\nmesh_size = 0.08\n",
                {"case.toml:2:", "geometry.mesh_size = 0.08", "violates: mesh_size <="}},
        BadCase{"missing_mesh",
                "[structure]\nmesh = \"nope.msh\"\n",
                {"case.toml:2:", "structure.mesh = \"nope.msh\"", "an existing mesh file"}},
        BadCase{"samples_below_nyquist",
                "[hbm]\nharmonics = 5\ntime_samples = 8\n",
                {"case.toml:3:", "hbm.time_samples = 8", "time_samples >= 2*harmonics+1 (= 11)"}},
        BadCase{"unknown_model",
                "[contact]\nmodel = \"coulomb\"\n",
                {"case.toml:2:", "contact.model = \"coulomb\"", "one of \"full3d\" | \"quasi3d\""}},
        BadCase{"equal_frequencies",
                "[continuation]\nfrequency_start_hz = 150\nfrequency_end_hz = 150\n",
                {"case.toml:3:", "continuation.frequency_end_hz", "!= frequency_start_hz"}},
        BadCase{"lumped_without_mass", "[structure]\ntype = \"lumped\"\nsectors = 1\n", {"structure.mass is required"}},
        BadCase{"damping_ratio_negative",
                "[modal]\ndamping_ratio = -0.01\n",
                {"case.toml:2:", "modal.damping_ratio = -0.01", "0 <= damping_ratio < 1"}},
        BadCase{"point_length",
                "[excitation]\npoint = [0.0, 0.35]\n",
                {"case.toml:2:", "excitation.point", "exactly 3 numbers"}},
        BadCase{"engine_orders_type",
                "[campbell]\nengine_orders = [\"one\"]\n",
                {"case.toml:2:", "campbell.engine_orders: expected integers"}},
        BadCase{"harmonic_index_range",
                "[modal]\nharmonic_indices = [0, 8]\n",
                {"case.toml:2:", "modal.harmonic_indices", "0 <= h < structure.sectors (8)"}},
        BadCase{"contact_angle_crossing",
                "[geometry]\nshroud_contact_angle_deg = 89\n",
                {"case.toml:2:", "geometry.shroud_contact_angle_deg = 89", "must not cross"}},
        BadCase{"nan_value",
                "[contact]\nfriction_coefficient = nan\n",
                {"case.toml:2:", "contact.friction_coefficient", "a finite number"}},
        BadCase{"lumped_matrix_not_square",
                "[structure]\ntype = \"lumped\"\nsectors = 1\nmass = [[1.0, 0.0]]\nstiffness = [[1.0]]\n",
                {"case.toml:4:", "structure.mass", "a square matrix"}},
        BadCase{"shooting_on_a_sector",
                "[response]\nstability_method = \"shooting\"\n",
                {"case.toml:2:", "response.stability_method = \"shooting\"", "a lumped structure"}},
        BadCase{"shooting_steps_range",
                "[response]\nshooting_steps = 100\n",
                {"case.toml:2:", "response.shooting_steps = 100", "256 <= value <= 65536"}},
        BadCase{"study_unknown_key",
                "[study]\nvary = { \"contact.preload\" = [0.0, 1.0] }\n",
                {"case.toml:2:", "'contact.preload' is not a case key", "did you mean 'contact.normal_preload'"}}),
    [](const ::testing::TestParamInfo<BadCase>& info) { return std::string(info.param.what); });

TEST(Case, LumpedCaseReadsMatricesAndElements) {
  const Case c = parse_case(R"(
[structure]
type = "lumped"
sectors = 1
mass = [[1.0, 0.0], [0.0, 2.0]]
stiffness = [[2.0, -1.0], [-1.0, 2.0]]
[excitation]
force = 1.5
dof = 1
[[contact.elements]]
x_dof = 0
normal_preload = 2.0
)",
                            "case.toml");
  EXPECT_EQ(c.structure.mass.rows(), 2);
  EXPECT_DOUBLE_EQ(c.structure.mass(1, 1), 2.0);
  EXPECT_DOUBLE_EQ(c.excitation.force[0], 1.5);
  ASSERT_EQ(c.contact.elements.size(), 1u);
  EXPECT_EQ(c.contact.elements[0].x_dof, 0);
  EXPECT_EQ(c.contact.elements[0].y_dof, -1);
  EXPECT_DOUBLE_EQ(*c.contact.elements[0].normal_preload, 2.0);
  EXPECT_FALSE(c.contact.elements[0].friction_coefficient.has_value());
}

TEST(Case, StudyValuesKeepTheirTomlText) {
  const Case c = parse_case(
      "[study]\nvary = { \"contact.normal_preload\" = [0.0, 0.25], \"contact.model\" = [\"1d\"] }\n", "case.toml");
  // Keys come in sorted order (TOML tables are unordered; sorting makes studies reproducible).
  ASSERT_EQ(c.study.vary.size(), 2u);
  EXPECT_EQ(c.study.vary[0].first, "contact.model");
  EXPECT_EQ(c.study.vary[0].second, (std::vector<std::string>{"\"1d\""}));
  EXPECT_EQ(c.study.vary[1].first, "contact.normal_preload");
  EXPECT_EQ(c.study.vary[1].second, (std::vector<std::string>{"0.0", "0.25"}));
}

}  // namespace
}  // namespace shroudsim::io
