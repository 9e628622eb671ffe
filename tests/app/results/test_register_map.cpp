// The results register map: the header at the addresses of map v1 (checked word by word
// against IEEE 754 encodings worked out by hand), one block per damage channel of the
// drivetrain (per planet and failure mode), nothing overlapping, the command block left to
// the clients, and docs/results-map.md equal to what the declaration generates.
#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "../../hal/no_alloc.hpp"
#include "model/drivetrain/description.hpp"
#include "results/register_map.hpp"

namespace {

using app::results::RegisterMap;
namespace mf = model::fatigue;

const mf::ChannelSet& paper_channels() {
  static const model::Drivetrain d = model::paper_2mw();
  static const mf::ChannelSet channels(d, mf::ChannelOptions{});
  return channels;
}

TEST(ResultsRegisterMap, TheHeaderKeepsTheAddressesOfMapVersionOne) {
  // Arrange
  const RegisterMap map(paper_channels());
  app::results::ResultsValues v;
  v.sequence = 0x00010002;
  v.status_word = app::results::kStatusRunning | app::results::kStatusCalibrated;
  v.calibration_generation = 7;
  v.stamp_ns = 86400LL * 1000000000LL + 999999999LL;  // 86 400.999... s → 86 400 s
  v.rotor_torque_nm = 361747.0f;                      // 0x48B0A260
  v.rotor_speed_rpm = 8.33f;                          // 0x410547AE
  v.indicators[7] = -12.5f;                           // 0xC1480000
  hal::RegisterImage img;
  // Act
  map.encode(v, img);
  // Assert
  EXPECT_EQ(img.count, map.register_count());
  EXPECT_EQ(img.words[0], app::results::kResultsMapVersion);
  EXPECT_EQ(img.words[1], 0x0021);
  EXPECT_EQ(img.words[3], 7);
  EXPECT_EQ(img.words[4], 0x0001);
  EXPECT_EQ(img.words[5], 0x0002);
  EXPECT_EQ(img.words[6], 0x0001);  // 86 400 = 0x00015180
  EXPECT_EQ(img.words[7], 0x5180);
  EXPECT_EQ(img.words[8], 0x48B0);
  EXPECT_EQ(img.words[9], 0xA260);
  EXPECT_EQ(img.words[10], 0x4105);
  EXPECT_EQ(img.words[11], 0x47AE);
  EXPECT_EQ(img.words[18], paper_channels().channel_count());
  EXPECT_EQ(img.words[134 + 14], 0xC148);  // indicator 7 at 134 + 2·7
  EXPECT_EQ(img.words[134 + 15], 0x0000);
  for (std::uint16_t a = 20; a < 134; ++a) EXPECT_EQ(img.words[a], 0) << "retired " << a;
}

TEST(ResultsRegisterMap, EveryDamageChannelHasItsBlockPerPlanetAndFailureMode) {
  // Arrange
  const mf::ChannelSet& cs = paper_channels();
  const RegisterMap map(cs, hal::WordOrder::kLowWordFirst);
  app::results::ResultsValues v;
  const std::size_t last = cs.channel_count() - 1;
  v.channels[last].damage = -12.5f;                                 // 0xC1480000
  v.channels[last].rul_h = std::numeric_limits<float>::infinity();  // 0x7F800000
  v.channels[last].load = 361747.0f;
  hal::RegisterImage img;
  // Act
  map.encode(v, img);
  // Assert: paper-2mw has 3 planets: each has its own channels, and so does every bearing.
  EXPECT_EQ(map.channel_count(), cs.channel_count());
  std::vector<std::string> names;
  for (const auto& e : map.entries()) names.push_back(e.name);
  auto has = [&](const std::string& n) {
    return std::find(names.begin(), names.end(), n) != names.end();
  };
  EXPECT_TRUE(has("channel.planet1.contact.ring-side-flank.damage"));
  EXPECT_TRUE(has("channel.planet3.bending.reversed-y_m.damage"));
  EXPECT_TRUE(has("channel.pb2.bearing.rul_h"));
  const std::uint16_t base = RegisterMap::kChannelBase + RegisterMap::kChannelStride * last;
  EXPECT_EQ(map.register_count(), base + RegisterMap::kChannelStride);
  EXPECT_EQ(img.words[base], 0x0000);  // low word first
  EXPECT_EQ(img.words[base + 1], 0xC148);
  EXPECT_EQ(img.words[base + 2], 0x0000);
  EXPECT_EQ(img.words[base + 3], 0x7F80);
  EXPECT_EQ(img.words[base + 6], 0xA260);
  EXPECT_EQ(img.words[base + 7], 0x48B0);
}

TEST(ResultsRegisterMap, NoTwoEntriesShareARegisterAndAllFitTheImage) {
  const RegisterMap map(paper_channels());
  std::vector<int> owner(map.register_count(), -1);
  for (std::size_t i = 0; i < map.entries().size(); ++i) {
    const auto& e = map.entries()[i];
    for (std::size_t k = 0; k < hal::register_count(e.type); ++k) {
      ASSERT_LT(e.address + k, owner.size()) << e.name;
      EXPECT_EQ(owner[e.address + k], -1) << e.name << " overlaps entry " << owner[e.address + k];
      owner[e.address + k] = static_cast<int>(i);
    }
  }
  EXPECT_LE(map.register_count(), hal::kMaxImageRegisters);
  // The largest drivetrain the fatigue model can hold fits the image too.
  EXPECT_LE(RegisterMap::kChannelBase + RegisterMap::kChannelStride * mf::kMaxChannels,
            hal::kMaxImageRegisters);
}

TEST(ResultsRegisterMap, EncodeLeavesTheCommandBlockToTheClientsAndAllocatesNothing) {
  // Arrange
  const RegisterMap map(paper_channels());
  hal::RegisterImage img;
  img.words[RegisterMap::kCommandStart] = 0xBEEF;
  app::results::ResultsValues v;
  // Act
  no_alloc::Scope scope;
  for (std::uint32_t i = 0; i < 100; ++i) {
    v.sequence = i;
    map.encode(v, img);
  }
  // Assert
  EXPECT_EQ(scope.allocations(), 0u);
  EXPECT_EQ(img.words[RegisterMap::kCommandStart], 0xBEEF);
}

TEST(ResultsRegisterMap, TheDocumentedTableIsTheOneTheDeclarationGenerates) {
  // Arrange: docs/results-map.md holds `drivetwin results-map` for paper-2mw.
  std::ifstream in(DRIVETWIN_SOURCE_DIR "/docs/results-map.md");
  ASSERT_TRUE(in) << "docs/results-map.md missing";
  std::stringstream doc;
  doc << in.rdbuf();
  // Act
  const std::string table = RegisterMap(paper_channels()).markdown();
  // Assert
  EXPECT_NE(doc.str().find(table), std::string::npos)
      << "docs/results-map.md is stale: regenerate it with `drivetwin results-map`";
}

}  // namespace
