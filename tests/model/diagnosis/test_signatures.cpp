// The signature catalogue of paper-2mw against the kinematics table of
// shared/reference/drivetrain-2mw.md (frequencies computed there by hand).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "model/diagnosis/signatures.hpp"

namespace {

namespace md = model::diagnosis;

const md::Hypothesis* find(const md::Catalogue& c, md::Effect e, const std::string& loc) {
  for (const auto& h : c.hypotheses)
    if (h.effect == e && h.location == loc) return &h;
  return nullptr;
}

bool has_line(const md::Hypothesis& h, double order, double tol) {
  return std::any_of(h.lines.begin(), h.lines.end(),
                     [&](const md::SignatureLine& l) { return std::abs(l.order - order) < tol; });
}

TEST(SignatureCatalogue, CoversEveryEffectOfTheContractAtItsTypicalLocations) {
  const md::Catalogue c = md::build_catalogue(model::paper_2mw(), {"b5", "b3"});
  EXPECT_EQ(c.reference_shaft, "hss");
  for (const char* g : {"sun", "planet", "g1", "g2", "g3", "g4"})
    EXPECT_NE(find(c, md::Effect::kToothCrack, g), nullptr) << g;
  for (const char* g : {"sun", "g1", "g2", "g3", "g4"})
    EXPECT_NE(find(c, md::Effect::kGearEccentricity, g), nullptr) << g;
  for (const char* b : {"b1", "b2", "b3", "b4", "b5", "b6", "pb"}) {
    EXPECT_NE(find(c, md::Effect::kBearingOuterRaceDefect, b), nullptr) << b;
    EXPECT_NE(find(c, md::Effect::kBearingInnerRaceDefect, b), nullptr) << b;
    EXPECT_NE(find(c, md::Effect::kBearingBallDefect, b), nullptr) << b;
  }
  for (const char* s : {"sun_shaft", "ims", "hss"})
    EXPECT_NE(find(c, md::Effect::kShaftUnbalance, s), nullptr) << s;
  for (const char* s : {"ims", "hss"})
    EXPECT_NE(find(c, md::Effect::kShaftMisalignment, s), nullptr) << s;
  EXPECT_NE(find(c, md::Effect::kPlanetPassModulation, "ring"), nullptr);
  EXPECT_NE(find(c, md::Effect::kHousingResonance, "b5"), nullptr);
  EXPECT_NE(find(c, md::Effect::kHousingResonance, "b3"), nullptr);
  EXPECT_EQ(find(c, md::Effect::kShaftUnbalance, "lss"), nullptr);  // the rotor's own shaft
  for (std::size_t i = 0; i < md::kEffectCount; ++i) {
    const auto e = static_cast<md::Effect>(i);
    EXPECT_EQ(md::effect_from_id(md::effect_id(e)), e);
  }
}

TEST(SignatureCatalogue, PutsTheLinesWhereTheReferenceKinematicsTableDoes) {
  // Paper point: hss 14.3032 Hz, high-speed mesh 371.884 Hz, intermediate mesh 72.987 Hz,
  // ims 3.4756 Hz, sun shaft 0.7933 Hz, carrier 0.1388 Hz, planet pass 0.4165 Hz,
  // b5 BPFO/BPFI 93.066/135.785 Hz, b3 BPFO 26.928 Hz (drivetrain-2mw.md).
  const md::Catalogue c = md::build_catalogue(model::paper_2mw(), {"b5", "b3"});
  const double hss = 14.3032;
  const double tol = 2e-4;  // orders; the table's rounding
  const auto* g4 = find(c, md::Effect::kToothCrack, "g4");
  ASSERT_NE(g4, nullptr);
  EXPECT_NEAR(g4->rate_order, 1.0, 1e-12);
  EXPECT_TRUE(has_line(*g4, (371.884 - 14.3032) / hss, tol));
  EXPECT_TRUE(has_line(*g4, (2 * 371.884 + 3 * 14.3032) / hss, tol));
  const auto* g3 = find(c, md::Effect::kToothCrack, "g3");
  EXPECT_TRUE(has_line(*g3, (371.884 + 3.4756) / hss, tol));
  const auto* g1 = find(c, md::Effect::kGearEccentricity, "g1");
  EXPECT_TRUE(has_line(*g1, (72.987 - 0.7933) / hss, tol));
  EXPECT_FALSE(has_line(*g1, (72.987 - 3 * 0.7933) / hss, tol));  // eccentricity: k ≤ 2
  const auto* ppm = find(c, md::Effect::kPlanetPassModulation, "ring");
  EXPECT_NEAR(ppm->rate_order, 0.4165 / hss, tol);
  const auto* b5 = find(c, md::Effect::kBearingOuterRaceDefect, "b5");
  EXPECT_EQ(b5->domain, md::Domain::kEnvelope);
  EXPECT_NEAR(b5->lines[0].order, 93.066 / hss, tol);
  EXPECT_NEAR(b5->tolerance, 0.02, 1e-12);
  const auto* b5i = find(c, md::Effect::kBearingInnerRaceDefect, "b5");
  EXPECT_TRUE(has_line(*b5i, (135.785 + 14.3032) / hss, tol));
  const auto* b3 = find(c, md::Effect::kBearingOuterRaceDefect, "b3");
  EXPECT_NEAR(b3->lines[0].order, 26.928 / hss, tol);
  const auto* mis = find(c, md::Effect::kShaftMisalignment, "ims");
  EXPECT_TRUE(has_line(*mis, 2 * 3.4756 / hss, tol));
  // The families name the features: the g4 crack's is the hss-spaced hs-mesh family.
  EXPECT_EQ(c.families[g4->family].text,
            "sidebands of the high-speed mesh spaced at the hss speed");
}

TEST(SignatureCatalogue, DropsLinesAboveTheAnalysisBand) {
  md::CatalogueConfig cfg;
  cfg.max_order = 30.0;
  const md::Catalogue c = md::build_catalogue(model::paper_2mw(), {"b5"}, cfg);
  for (const auto& h : c.hypotheses)
    for (const auto& l : h.lines) EXPECT_LE(l.order, 30.0);
}

}  // namespace
