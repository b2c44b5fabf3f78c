// The knobs of `study --convergence` (study/trade_design.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "study/trade_design.hpp"

using namespace shroudsim;

namespace {
const study::Knob* find(const std::vector<study::Knob>& knobs, const std::string& key) {
  auto it = std::find_if(knobs.begin(), knobs.end(), [&](const study::Knob& k) { return k.key == key; });
  return it == knobs.end() ? nullptr : &*it;
}
}  // namespace

TEST(TradeDesign, AGeneratedSectorVariesEveryKnobAndItsMeshDoublesTheDofsPerStep) {
  io::Case c;  // the default case: a generated sector, full3d, H and N given
  c.geometry.mesh_size = 0.02;
  c.contact.pairs = 5;
  const auto knobs = study::convergence_knobs(c);
  for (const char* key :
       {"geometry.mesh_size", "contact.pairs", "modal.modes", "modal.residual_flexibility", "hbm.harmonics",
        "hbm.time_samples", "contact.tangential_update", "contact.model", "hbm.jacobian"})
    EXPECT_NE(find(knobs, key), nullptr) << key;
  const study::Knob* mesh = find(knobs, "geometry.mesh_size");
  ASSERT_EQ(mesh->values.size(), static_cast<std::size_t>(study::kMeshLadder));
  for (std::size_t i = 1; i < mesh->values.size(); ++i) {
    const double ratio = std::stod(mesh->values[i - 1]) / std::stod(mesh->values[i]);
    EXPECT_NEAR(ratio * ratio * ratio, 2.0, 1e-12);  // h^-3 ~ DOFs: twice per step
  }
  // The finest H is the reference, with 4 N samples so that 2 H + 1 <= N.
  const study::Knob* h = find(knobs, "hbm.harmonics");
  ASSERT_FALSE(h->reference.empty());
  EXPECT_GE(std::stoi(h->reference[0].second), 2 * std::stoi(h->values.back()) + 1);
  // Every N value resolves the case's H.
  for (const std::string& n : find(knobs, "hbm.time_samples")->values) EXPECT_GE(std::stoi(n), 2 * c.hbm.harmonics + 1);
}

TEST(TradeDesign, TheExactOneDimensionalLawHasNoSamplingKnobs) {
  io::Case c;
  c.structure.type = io::StructureType::lumped;
  c.contact.model = contact::Model::one_d_exact;
  EXPECT_TRUE(study::convergence_knobs(c).empty());
  c.contact.model = contact::Model::one_d;
  const auto knobs = study::convergence_knobs(c);
  EXPECT_EQ(find(knobs, "geometry.mesh_size"), nullptr);
  EXPECT_EQ(find(knobs, "contact.model"), nullptr);  // 1d has no quasi3d / full3d alternative
  EXPECT_NE(find(knobs, "hbm.time_samples"), nullptr);
}
