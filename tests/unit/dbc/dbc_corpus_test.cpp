// A real-world DBC from the SavvyCAN corpus (Nissan Leaf powertrain bus) loads,
// and its Motorola signals decode like the naive bit walker says.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "daemon/dbc/dbc_codec.h"
#include "daemon/dbc/dbc_parser.h"
#include "tests/unit/dbc/naive_bit_codec.h"

namespace resolver::dbc {
namespace {

constexpr const char* kLeafDbc = RESOLVER_SHARED_DIR "/corpus/savvycan/LeafPowertrainBus.dbc";

TEST(DbcCorpus, LeafPowertrainBusLoads) {
  if (!std::filesystem::exists(kLeafDbc)) GTEST_SKIP() << "corpus file absent: " << kLeafDbc;
  const Database db = load_dbc_file(kLeafDbc);

  // As many messages as the file has BO_ lines (counted here, not assumed).
  std::ifstream in(kLeafDbc);
  std::string line;
  std::size_t bo_lines = 0;
  while (std::getline(in, line)) bo_lines += line.rfind("BO_ ", 0) == 0 ? 1U : 0U;
  EXPECT_EQ(db.messages.size(), bo_lines);

  const Message* inv = db.find_message(0x1DA, false);
  ASSERT_NE(inv, nullptr);
  EXPECT_EQ(inv->name, "InverterStatus");
  EXPECT_EQ(inv->sender, "Inverter");
  const Signal* amps = inv->find_signal("Amps");
  const Signal* rpm = inv->find_signal("RPM");
  ASSERT_NE(amps, nullptr);
  ASSERT_NE(rpm, nullptr);
  EXPECT_EQ(amps->order, ByteOrder::kBigEndian);
  EXPECT_TRUE(amps->is_signed);
  EXPECT_EQ(amps->length, 11U);
  EXPECT_EQ(amps->factor, 0.5);
  EXPECT_EQ(rpm->start_bit, 39U);
  EXPECT_EQ(db.find_message("BatteryStatus2")->find_signal("MaxPower")->unit, "kW");

  // Every signal of the file decodes random payloads like the bit walker.
  std::mt19937_64 rng(7);
  for (const Message& m : db.messages) {
    for (const Signal& s : m.signals) {
      for (int i = 0; i < 100; ++i) {
        std::array<std::uint8_t, 8> d{};
        for (auto& b : d) b = static_cast<std::uint8_t>(rng());
        ASSERT_EQ(extract_raw(s, d), test::naive_extract(s, d)) << m.name << "." << s.name;
      }
    }
  }
}

}  // namespace
}  // namespace resolver::dbc
