// Persistence of the online accumulator (app/persistence/accumulator_store.hpp): round trip,
// damaged files reported with the file and what is wrong, fallback to the last good copy,
// and a resumed run that ends with exactly the damage of an uninterrupted one.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "model/fatigue/damage_accumulator.hpp"
#include "persistence/accumulator_store.hpp"

namespace {
namespace fs = std::filesystem;
namespace mf = model::fatigue;
using app::persistence::AccumulatorStore;
using app::persistence::LoadStatus;
using testing::HasSubstr;

class AccumulatorStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           (std::string("drivetwin_store_") +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Steps `acc` through a deterministic torque/speed history, steps [from, to).
  static void drive(mf::DamageAccumulator& acc, const mf::ChannelSet& cs, int from, int to) {
    for (int i = from; i < to; ++i) {
      const double torque = 1.23e6 * (0.55 + 0.5 * std::sin(0.013 * i));
      const double rpm = 9.0 + 5.0 * std::sin(0.007 * i + 0.3);
      (void)acc.step(cs.quasi_static_loads(torque), rpm, 100);
    }
  }
  std::vector<char> read_bytes(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  void write_bytes(const fs::path& p, const std::vector<char>& b) {
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(b.data(), static_cast<std::streamsize>(b.size()));
  }

  fs::path dir_;
  model::Drivetrain drivetrain_ = model::paper_2mw();
  mf::ChannelSet channels_{drivetrain_, mf::ChannelOptions{}};
};

TEST_F(AccumulatorStoreTest, SavedStateLoadsBackBitForBit) {
  // Arrange
  mf::DamageAccumulator acc(channels_, mf::AccumulatorConfig{});
  drive(acc, channels_, 0, 500);
  const AccumulatorStore store(dir_ / "acc.state");
  std::string error;
  // Act
  ASSERT_TRUE(store.save(acc.state(), &error)) << error;
  auto loaded = std::make_unique<mf::AccumulatorState>();
  const auto r = store.load(*loaded);
  // Assert
  EXPECT_EQ(r.status, LoadStatus::kLoaded) << r.message;
  EXPECT_EQ(std::memcmp(loaded.get(), &acc.state(), sizeof(mf::AccumulatorState)), 0);
  EXPECT_FALSE(fs::exists(store.temp_path()));
}

TEST_F(AccumulatorStoreTest, FirstStartSaysThereIsNoStateInsteadOfSilentlyStartingFromZero) {
  const AccumulatorStore store(dir_ / "acc.state");
  auto s = std::make_unique<mf::AccumulatorState>();
  const auto r = store.load(*s);
  EXPECT_EQ(r.status, LoadStatus::kNoState);
  EXPECT_THAT(r.message, HasSubstr("no saved state"));
  EXPECT_THAT(r.message, HasSubstr("acc.state"));
}

TEST_F(AccumulatorStoreTest, BitFlipIsDetectedByTheCrcAndTheLastGoodCopyIsUsed) {
  // Arrange: two saves, so acc.state.bak holds the first state; then one bit of the
  // newest file's payload flips.
  mf::DamageAccumulator acc(channels_, mf::AccumulatorConfig{});
  const AccumulatorStore store(dir_ / "acc.state");
  std::string error;
  drive(acc, channels_, 0, 200);
  ASSERT_TRUE(store.save(acc.state(), &error)) << error;
  auto first = std::make_unique<mf::AccumulatorState>(acc.state());
  drive(acc, channels_, 200, 400);
  ASSERT_TRUE(store.save(acc.state(), &error)) << error;
  auto bytes = read_bytes(store.path());
  bytes[24 + 1000] ^= 0x10;
  write_bytes(store.path(), bytes);
  // Act
  auto loaded = std::make_unique<mf::AccumulatorState>();
  const auto r = store.load(*loaded);
  // Assert
  EXPECT_EQ(r.status, LoadStatus::kLoadedBackup);
  EXPECT_THAT(r.message, HasSubstr("CRC-32 mismatch"));
  EXPECT_THAT(r.message, HasSubstr("acc.state.bak"));
  EXPECT_EQ(std::memcmp(loaded.get(), first.get(), sizeof(mf::AccumulatorState)), 0);
}

TEST_F(AccumulatorStoreTest, TruncatedFileIsReportedWithItsLength) {
  mf::DamageAccumulator acc(channels_, mf::AccumulatorConfig{});
  const AccumulatorStore store(dir_ / "acc.state");
  std::string error;
  drive(acc, channels_, 0, 100);
  ASSERT_TRUE(store.save(acc.state(), &error)) << error;
  ASSERT_TRUE(store.save(acc.state(), &error)) << error;  // now a .bak exists too
  auto bytes = read_bytes(store.path());
  bytes.resize(bytes.size() / 2);
  write_bytes(store.path(), bytes);
  auto loaded = std::make_unique<mf::AccumulatorState>();
  const auto r = store.load(*loaded);
  EXPECT_EQ(r.status, LoadStatus::kLoadedBackup);
  EXPECT_THAT(r.message, HasSubstr("truncated: " + std::to_string(bytes.size()) + " bytes"));
}

TEST_F(AccumulatorStoreTest, WrongVersionAndForeignFilesAreNamedAndNeverLoaded) {
  // Arrange: a state file of format version 2 (bytes 8..11) and a foreign backup.
  mf::DamageAccumulator acc(channels_, mf::AccumulatorConfig{});
  const AccumulatorStore store(dir_ / "acc.state");
  std::string error;
  ASSERT_TRUE(store.save(acc.state(), &error)) << error;
  auto bytes = read_bytes(store.path());
  bytes[8] = 2;
  write_bytes(store.path(), bytes);
  write_bytes(store.backup_path(),
              std::vector<char>{'h', 'e', 'l', 'l', 'o', ' ', 'w', 'o', 'r', 'l', 'd', '!', ' ',
                                'n', 'o', 't', ' ', 'a', ' ', 's', 't', 'a', 't', 'e', '.'});
  // Act
  auto loaded = std::make_unique<mf::AccumulatorState>();
  loaded->valid_steps = 12345;
  const auto r = store.load(*loaded);
  // Assert: both problems named, nothing loaded (the caller must not start from zero).
  EXPECT_EQ(r.status, LoadStatus::kCorrupt);
  EXPECT_THAT(r.message, HasSubstr("file format version 2, this build reads version 1"));
  EXPECT_THAT(r.message, HasSubstr("not a drivetwin accumulator state file"));
  EXPECT_EQ(loaded->valid_steps, 12345u);
}

TEST_F(AccumulatorStoreTest, ACorruptCurrentFileNeverReplacesTheGoodBackupOnTheNextSave) {
  mf::DamageAccumulator acc(channels_, mf::AccumulatorConfig{});
  const AccumulatorStore store(dir_ / "acc.state");
  std::string error;
  drive(acc, channels_, 0, 100);
  ASSERT_TRUE(store.save(acc.state(), &error)) << error;
  ASSERT_TRUE(store.save(acc.state(), &error)) << error;
  const auto good_backup = read_bytes(store.backup_path());
  auto bytes = read_bytes(store.path());
  bytes[40] ^= 1;
  write_bytes(store.path(), bytes);
  ASSERT_TRUE(store.save(acc.state(), &error)) << error;
  EXPECT_EQ(read_bytes(store.backup_path()), good_backup);
}

TEST_F(AccumulatorStoreTest, ResumedRunEndsWithExactlyTheDamageOfAnUninterruptedRun) {
  // Arrange: uninterrupted reference over 2000 steps.
  mf::DamageAccumulator reference(channels_, mf::AccumulatorConfig{});
  drive(reference, channels_, 0, 2000);
  // Act: 1000 steps, save, a new process (new accumulator) loads and continues.
  const AccumulatorStore store(dir_ / "acc.state");
  std::string error;
  {
    mf::DamageAccumulator before(channels_, mf::AccumulatorConfig{});
    drive(before, channels_, 0, 1000);
    ASSERT_TRUE(store.save(before.state(), &error)) << error;
  }
  mf::DamageAccumulator resumed(channels_, mf::AccumulatorConfig{});
  auto saved = std::make_unique<mf::AccumulatorState>();
  ASSERT_TRUE(store.load(*saved).ok());
  ASSERT_TRUE(resumed.restore(*saved));
  drive(resumed, channels_, 1000, 2000);
  // Assert: every channel's damage, time and revolutions identical (integer time, same sums).
  for (std::size_t c = 0; c < channels_.channel_count(); ++c) {
    EXPECT_EQ(resumed.damage(c), reference.damage(c)) << channels_.channel(c).component;
  }
  EXPECT_EQ(resumed.state().elapsed_ticks, reference.state().elapsed_ticks);
  EXPECT_EQ(resumed.state().rotor_rev_q, reference.state().rotor_rev_q);
  EXPECT_EQ(std::memcmp(&resumed.state(), &reference.state(), sizeof(mf::AccumulatorState)), 0);
}

}  // namespace
