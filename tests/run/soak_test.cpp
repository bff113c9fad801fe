// The soak on the CPU (`phyxel soak`, docs/performance.md "Soak"): scenes/soak.json, whose
// scalpel, grasper and aspirator repeat a 0.4 s cycle (cut, tear, aspirate, grasp and release)
// 0.4 mm further along the block each time ("repeat_shift"), for soak_steps() steps: resident
// memory flat after the first tenth (the warm-up; the heap in use grows only by what the
// severed pairs hold), the kinetic energy finite and bounded in
// every tenth, every kind of topology edit done in every tenth, the last included, and the final
// state bit-identical between the uninterrupted run and a second run stopped half-way and
// resumed from its checkpoint. The step rate per tenth is recorded, never judged.
// Release ctest only (the run area is not in the sanitizer job).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdint>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/physics/physics_fixtures.h"
#include "tests/support/support.h"

namespace phyxel {
namespace {

namespace fs = std::filesystem;
using test::read_json;

// A multiple of twice the tool chunk (64 substeps; the scene's steps have one): the checkpoint
// half-way and the end fall on the aspirator's grid, so the stopped run is the uninterrupted
// one's first half. 49 152 steps (about 37 cycles) take about 50 s of one core per run
// (docs/performance.md, "Soak"); PHYXEL_SOAK_STEPS sets another count (a multiple of 128).
int64_t soak_steps() {
  const char* steps = std::getenv("PHYXEL_SOAK_STEPS");
  return steps ? std::stoll(steps) : 49152;
}
// Resident memory may grow this much from the end of the first tenth to the end of the last.
constexpr long kRssGrowthKib = 4096;
// The heap in use after the first tenth grows only by what the severed pairs hold (the
// solver's log entry, 16 B, and the aspirator's set node and bucket, ~40 B; both vectors and
// the set's buckets grow by doubling) and by at most this besides.
constexpr long kHeapBytesPerSeveredPair = 128;
constexpr long kHeapSlackBytes = 64 * 1024;

int soak(const std::string& args, const fs::path& dir) {
  const std::string command =
      "timeout 800 " + std::string(PHYXEL_BINARY_DIR) + "/app/phyxel soak " + PHYXEL_SOURCE_DIR +
      "/scenes/soak.json --threads 1 --quiet " + args + " >" + (dir / "log.txt").string() + " 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(Soak, MemoryFlatEnergyBoundedAndResumedBitIdentical) {
  const int64_t total = soak_steps();
  const fs::path dir = test::test_output_dir("soak");
  const std::string steps = " --steps " + std::to_string(total);
  ASSERT_EQ(soak(steps + " --out " + (dir / "full").string(), dir), 0);
  const nlohmann::json full = read_json(dir / "full" / "soak.json");
  const int64_t chunk = 64 / full["substeps"].get<int64_t>();  // steps per tool chunk
  ASSERT_EQ(total / 2 % chunk, 0) << "the halves must fall on the tool chunks' grid";
  ASSERT_EQ(full["steps_done"], total);
  EXPECT_FALSE(full["non_finite"].get<bool>());
  EXPECT_FALSE(full["unstable"].get<bool>());

  const auto& tenths = full["tenths"];
  ASSERT_EQ(tenths.size(), 10u);
  // The tissue: 12 x 47 x 8 mm at 1000 kg/m^3, 4.5 g; moving everywhere at the scalpel's
  // 0.18 m/s it would hold 7.3e-5 J (aspirated phyxels not counted; no gravity, so pieces cut
  // loose come to rest). Every tenth cuts or tears pairs and grips; the last one (3.7 cycles)
  // also cuts, tears and aspirates (an aspiration takes about two cycles: at this length one
  // tenth of ten has none, docs/performance.md "Soak").
  for (const auto& t : tenths) {
    EXPECT_TRUE(t["finite"].get<bool>()) << t.dump();
    EXPECT_LT(t["kinetic_energy_j"].get<double>(), 1e-4) << t.dump();
    EXPECT_GE(t["kinetic_energy_j"].get<double>(), 0.0) << t.dump();
    EXPECT_GT(t["cut_pairs"].get<int64_t>() + t["torn_pairs"].get<int64_t>(), 0) << t.dump();
    EXPECT_GT(t["grips"].get<int64_t>(), 0) << t.dump();
  }
  for (const char* edit : {"cut_pairs", "torn_pairs", "aspirated_phyxels", "grips"})
    EXPECT_GT(tenths[9][edit].get<int64_t>(), 0) << edit << " in " << tenths[9].dump();
  RecordProperty("last_tenth_edits", tenths[9].dump());
  const long growth = tenths[9]["rss_kib"].get<long>() - tenths[0]["rss_kib"].get<long>();
  EXPECT_LE(growth, kRssGrowthKib) << full.dump(2);
  RecordProperty("rss_growth_kib", std::to_string(growth));
  const long heap_growth =
      tenths[9]["heap_bytes"].get<long>() - tenths[1]["heap_bytes"].get<long>();
  const long pairs_added =
      tenths[9]["severed_pairs_held"].get<long>() - tenths[1]["severed_pairs_held"].get<long>();
  EXPECT_GT(pairs_added, 0);
  EXPECT_LE(heap_growth, kHeapBytesPerSeveredPair * pairs_added + kHeapSlackBytes) << full.dump(2);
  RecordProperty("heap_growth_bytes", std::to_string(heap_growth));
  RecordProperty("severed_pairs_added", std::to_string(pairs_added));
  RecordProperty("steps_per_s_second_tenth",
                 std::to_string(tenths[1]["steps_per_s"].get<double>()));
  RecordProperty("steps_per_s_last_tenth", std::to_string(tenths[9]["steps_per_s"].get<double>()));
  // Every topology edit: cuts and tears (severed pairs, some torn), aspiration, a grip.
  EXPECT_GT(full["severed_pairs"].get<int64_t>(), full["torn_pairs"].get<int64_t>());
  EXPECT_GT(full["torn_pairs"].get<int64_t>(), 0);
  EXPECT_GT(full["aspiration_events"].get<int64_t>(), 0);
  bool held = false;
  for (const auto& t : full["tools"]) held = held || t["max_held"].get<int>() > 0;
  EXPECT_TRUE(held);

  // A second run, stopped half-way with a checkpoint and resumed: the same final state.
  const std::string half =
      " --steps " + std::to_string(total / 2) + " --checkpoint-every " + std::to_string(total / 2);
  ASSERT_EQ(soak(half + " --out " + (dir / "part").string(), dir), 0);
  ASSERT_EQ(soak(steps + " --resume " + (dir / "part").string(), dir), 0);
  const nlohmann::json resumed = read_json(dir / "part" / "soak.json");
  EXPECT_EQ(resumed["resumed_from_step"], total / 2);
  EXPECT_EQ(resumed["steps_done"], total);
  EXPECT_EQ(resumed["state_hash"], full["state_hash"]);
  EXPECT_EQ(resumed["severed_pairs"], full["severed_pairs"]);
  EXPECT_EQ(resumed["aspiration_events"], full["aspiration_events"]);
}

}  // namespace
}  // namespace phyxel
