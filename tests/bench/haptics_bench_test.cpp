// `phyxel bench --haptics` end to end, short: the CSV and JSON it writes have their columns and
// finite values, and the haptic loop ticked. Timing never decides the test.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "tests/physics/physics_fixtures.h"
#include "tests/support/support.h"

namespace phyxel {
namespace {

using phyxel::test::read_text;

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  for (std::string cell; std::getline(ss, cell, ',');) out.push_back(cell);
  if (!line.empty() && line.back() == ',') out.push_back("");
  return out;
}

// The CSV's rows as column -> cell.
std::vector<std::map<std::string, std::string>> read_csv(const std::filesystem::path& p) {
  std::stringstream in(read_text(p));
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> header = split(line);
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    const std::vector<std::string> cells = split(line);
    EXPECT_EQ(cells.size(), header.size()) << line;
    std::map<std::string, std::string> row;
    for (size_t c = 0; c < header.size() && c < cells.size(); ++c) row[header[c]] = cells[c];
    rows.push_back(row);
  }
  return rows;
}

double finite_number(const std::map<std::string, std::string>& row, const std::string& column) {
  const auto it = row.find(column);
  EXPECT_NE(it, row.end()) << column;
  if (it == row.end()) return NAN;
  char* end = nullptr;
  const double v = std::strtod(it->second.c_str(), &end);
  EXPECT_FALSE(it->second.empty()) << column;
  EXPECT_EQ(*end, '\0') << column << " = " << it->second;
  EXPECT_TRUE(std::isfinite(v)) << column << " = " << it->second;
  return v;
}

TEST(BenchHaptics, ShortCpuRunWritesFiniteCsvAndJson) {
  const auto dir = test::test_output_dir("bench_haptics");
  const auto err = dir / "stderr.txt";
  const std::string cmd = std::string(PHYXEL_BINARY_DIR) +
                          "/app/phyxel bench --haptics --seconds 0.5 --sizes 2000 --device cpu "
                          "--repeats 1 --steps 3 --threads 1 --scene " +
                          std::string(PHYXEL_SOURCE_DIR) + "/scenes/probe_indent.json --out " +
                          dir.string() + " >/dev/null 2>" + err.string();
  const int status = std::system(cmd.c_str());
  ASSERT_EQ(WEXITSTATUS(status), 0) << read_text(err);

  const auto rows = read_csv(dir / "haptics.csv");
  ASSERT_EQ(rows.size(), 3u);  // idle loop, loop with the solver, one contact size
  EXPECT_EQ(rows[0].at("part"), "loop_idle");
  EXPECT_EQ(rows[1].at("part"), "loop_solver");
  EXPECT_EQ(rows[2].at("part"), "contact");
  for (size_t r = 0; r < 2; ++r) {
    for (const char* c : {"period_mean_ms", "period_p99_ms", "period_max_ms", "overruns",
                          "max_force_jump_n", "max_hand_force_n", "seconds"})
      finite_number(rows[r], c);
    EXPECT_GT(finite_number(rows[r], "ticks"), 0) << rows[r].at("part");
  }
  EXPECT_GT(finite_number(rows[1], "phyxels"), 1000);
  EXPECT_GT(finite_number(rows[1], "physics_steps_per_s"), 0);
  EXPECT_GT(finite_number(rows[1], "real_time_factor"), 0);
  for (const char* c :
       {"phyxels", "step_ms_no_tool", "step_ms_tool", "contact_share_percent", "candidates"})
    finite_number(rows[2], c);
  EXPECT_GT(finite_number(rows[2], "candidates"), 0);
  EXPECT_EQ(rows[2].at("finite"), "true");

  const nlohmann::json json = test::read_json(dir / "haptics.json");
  ASSERT_EQ(json.at("haptic_loop").size(), 2u);
  ASSERT_EQ(json.at("contact").size(), 1u);
  for (const nlohmann::json& row : json.at("haptic_loop")) {
    EXPECT_GT(row.at("ticks").get<double>(), 0);
    for (const char* c : {"period_mean_ms", "period_p99_ms", "period_max_ms", "max_force_jump_n"})
      EXPECT_TRUE(std::isfinite(row.at(c).get<double>())) << c;
  }
  const nlohmann::json& contact = json.at("contact")[0];
  for (const char* c : {"step_ms_no_tool", "step_ms_tool", "contact_share_percent"})
    EXPECT_TRUE(std::isfinite(contact.at(c).get<double>())) << c;
}

}  // namespace
}  // namespace phyxel
