// .vtp point files (ASCII and binary) and the `phyxel run` command line end to end.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "engine/run/vtp_writer.h"
#include "tests/physics/physics_fixtures.h"
#include "tests/support/support.h"

namespace phyxel {
namespace {

using phyxel::test::read_text;

struct Written {
  PhyxelSet set;
  PointState state;
};

Written sample_state() {
  Written w;
  w.set = sample_scene(
      test::box_scene(Vec3(0, 0, 0), Vec3(0.005, 0.0025, 0.0025), 0.0025, test::tissue()));
  for (size_t i = 0; i < w.set.size(); ++i) {
    w.state.displacement.push_back(Vec3(0.001 * i, 0, -0.5));
    w.state.velocity.push_back(Vec3(0, 2.0 * i, 0));
    w.state.von_mises.push_back(10.0 * i);
  }
  return w;
}

TEST(VtpWriter, AsciiFileHasPointsAndEveryArray) {
  const Written w = sample_state();
  const auto file = test::test_output_dir("vtp_ascii") / "points.vtp";
  write_points_vtp(file, w.set, w.state, false);
  const std::string text = read_text(file);
  EXPECT_NE(text.find("NumberOfPoints=\"" + std::to_string(w.set.size()) + "\""),
            std::string::npos);
  for (const char* name : {"rest_position", "displacement", "velocity", "von_mises", "flags",
                           "connectivity", "offsets"})
    EXPECT_NE(text.find("Name=\"" + std::string(name) + "\""), std::string::npos) << name;
  EXPECT_EQ(text.find("nan"), std::string::npos);
  // The first point is written at its deformed position x0 + u = (0, 0, -0.5).
  const size_t points = text.find("<Points>");
  const size_t values = text.find('>', text.find("<DataArray", points)) + 1;
  std::istringstream first(text.substr(values, 200));
  double x, y, z;
  first >> x >> y >> z;
  EXPECT_DOUBLE_EQ(x, 0);
  EXPECT_DOUBLE_EQ(y, 0);
  EXPECT_DOUBLE_EQ(z, -0.5);
  EXPECT_FALSE(std::filesystem::exists(file.string() + ".tmp"));
}

// The ASCII values are written by std::to_chars (engine/run/vtp_writer.cpp) exactly as a stream
// at precision 17 writes them, and read back to the same doubles: awkward values included.
TEST(VtpWriter, AsciiValuesAreTheStreamsDigitsAndReadBackExactly) {
  Written w = sample_state();
  const std::array<double, 9> awkward = {0.1,  1.0 / 3.0,     -2.5e10,       1e-300, 4.9e-324,
                                         -0.0, 123456789.125, 6.02214076e23, -1e-7};
  for (size_t i = 0; i < w.set.size(); ++i)
    w.state.displacement[i] =
        Vec3(awkward[(3 * i) % 9], awkward[(3 * i + 1) % 9], awkward[(3 * i + 2) % 9]);
  const auto file = test::test_output_dir("vtp_ascii_exact") / "points.vtp";
  write_points_vtp(file, w.set, w.state, false);
  const std::string text = read_text(file);
  const size_t array = text.find("Name=\"displacement\"");
  ASSERT_NE(array, std::string::npos);
  const size_t values = text.find('>', array) + 1;
  std::istringstream in(text.substr(values, text.find("</DataArray>", values) - values));
  for (size_t i = 0; i < w.set.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      std::string token;
      ASSERT_TRUE(in >> token) << i;
      std::ostringstream expected;
      expected.precision(17);
      expected << w.state.displacement[i][c];
      EXPECT_EQ(token, expected.str()) << i << " " << c;
      EXPECT_EQ(std::strtod(token.c_str(), nullptr), w.state.displacement[i][c]) << token;
    }
  }
}

TEST(VtpWriter, BinaryFileHasAppendedBlocksOfTheRightSize) {
  const Written w = sample_state();
  const auto file = test::test_output_dir("vtp_binary") / "points.vtp";
  write_points_vtp(file, w.set, w.state, true);
  const std::string text = read_text(file);
  const size_t start = text.find("<AppendedData encoding=\"raw\">\n_");
  ASSERT_NE(start, std::string::npos);
  // First block: the points, n * 3 doubles, preceded by its UInt64 byte count.
  uint64_t bytes = 0;
  std::memcpy(&bytes, text.data() + text.find('_', start) + 1, sizeof bytes);
  EXPECT_EQ(bytes, w.set.size() * 3 * sizeof(double));
}

TEST(VtpWriter, BinaryFileHasEveryBlockWhereItsOffsetSaysWithContact) {
  Written w = sample_state();
  const size_t n = w.set.size();
  for (size_t i = 0; i < n; ++i) w.state.contact.push_back(i % 3 == 0 ? 1 : 0);
  const auto file = test::test_output_dir("vtp_binary_contact") / "points.vtp";
  write_points_vtp(file, w.set, w.state, true);
  const std::string text = read_text(file);
  const size_t data = text.find('_', text.find("<AppendedData encoding=\"raw\">")) + 1;
  ASSERT_NE(data, std::string::npos + 1);
  size_t blocks = 0, end = 0;
  for (size_t at = text.find("<DataArray"); at < data; at = text.find("<DataArray", at + 1)) {
    const std::string tag = text.substr(at, text.find('>', at) - at);
    auto attr = [&tag](const std::string& key) {
      const size_t v = tag.find(key + "=\"") + key.size() + 2;
      return tag.substr(v, tag.find('"', v) - v);
    };
    const size_t width = attr("type") == "UInt32" ? 4 : 8;
    const uint64_t expected = n * std::stoul(attr("NumberOfComponents")) * width;
    const size_t block = data + std::stoull(attr("offset"));
    uint64_t bytes = 0;
    ASSERT_LE(block + sizeof bytes, text.size()) << tag;
    std::memcpy(&bytes, text.data() + block, sizeof bytes);
    EXPECT_EQ(bytes, expected) << tag;
    if (tag.find("Name=\"contact\"") != std::string::npos) {
      for (size_t i = 0; i < n && block + 8 + 4 * (i + 1) <= text.size(); ++i) {
        uint32_t c = 0;
        std::memcpy(&c, text.data() + block + 8 + 4 * i, 4);
        EXPECT_EQ(c, w.state.contact[i]) << "phyxel " << i;
      }
    }
    end = block + sizeof bytes + bytes;
    ++blocks;
  }
  EXPECT_EQ(blocks, 9u);  // points, five arrays, contact, connectivity, offsets
  EXPECT_EQ(text.compare(end, 16, "\n</AppendedData>"), 0);
}

TEST(VtpWriter, UnwritableFolderNamesTheFile) {
  const Written w = sample_state();
  try {
    write_points_vtp("/nonexistent-folder/points.vtp", w.set, w.state, false);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-folder/points.vtp"), std::string::npos);
  }
}

// Runs the phyxel binary; returns the exit status and what it printed on stderr (kept in a
// folder of the calling test's own: ctest runs tests in parallel).
std::pair<int, std::string> phyxel(const std::string& args) {
  const std::filesystem::path err =
      test::test_output_dir(std::string("stderr_") +
                            ::testing::UnitTest::GetInstance()->current_test_info()->name()) /
      "stderr.txt";
  const test::Ran ran = test::run_phyxel(args, err);
  return {ran.status, ran.err};
}

TEST(PhyxelRun, DemoSceneWritesSummaryAndPoints) {
  const auto dir = test::test_output_dir("cli_demo");
  const auto [code, err] = phyxel("run " + std::string(PHYXEL_SOURCE_DIR) +
                                  "/scenes/beam.json --steps 20 --threads 1 --out " + dir.string());
  ASSERT_EQ(code, 0) << err;
  const nlohmann::json s = nlohmann::json::parse(read_text(dir / "summary.json"));
  EXPECT_EQ(s["phyxels"], 41 * 9 * 9);
  EXPECT_EQ(s["steps_done"], 20);
  EXPECT_EQ(s["non_finite"], false);
  EXPECT_GT(s["substeps_per_step"].get<int>(), 1);  // the demo asks for dt above the bound
  EXPECT_FALSE(s["substep_reason"].get<std::string>().empty());
  EXPECT_LE(s["dt_used"].get<double>(), s["dt_stable_bound"].get<double>());
  for (const char* key : {"device", "wall_seconds", "kinetic_energy", "strain_energy",
                          "max_displacement", "stopped_at_rest", "dt_requested"})
    EXPECT_TRUE(s.contains(key)) << key;
  EXPECT_TRUE(std::filesystem::exists(dir / "points_000020.vtp"));
  EXPECT_NE(err.find("substeps"), std::string::npos) << err;  // and it says so
}

TEST(PhyxelRun, MissingSceneIsOneClearLine) {
  const auto [code, err] =
      phyxel("run /nonexistent/scene.json --out " + test::test_output_dir("cli_missing").string());
  EXPECT_EQ(code, 1);
  EXPECT_NE(err.find("/nonexistent/scene.json"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
}

TEST(PhyxelRun, BadMaterialExitsNonZeroNamingTheJsonPath) {
  const auto dir = test::test_output_dir("cli_bad_material");
  std::string scene = read_text(std::string(PHYXEL_SOURCE_DIR) + "/scenes/beam.json");
  const size_t at = scene.find("\"poisson\"");
  ASSERT_NE(at, std::string::npos);
  scene.replace(at, scene.find(',', at) - at, "\"poisson\": 0.7");
  std::ofstream(dir / "bad.json") << scene;
  const auto [code, err] = phyxel("run " + (dir / "bad.json").string() + " --out " + dir.string());
  EXPECT_EQ(code, 1);
  EXPECT_NE(err.find("bad.json"), std::string::npos) << err;
  EXPECT_NE(err.find("objects[0].material.poisson"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
}

TEST(PhyxelRun, UnknownOptionAndMissingValueAreUsageErrors) {
  auto [code, err] = phyxel("run scene.json --stepz 3");
  EXPECT_EQ(code, 2);
  EXPECT_NE(err.find("--stepz"), std::string::npos) << err;
  std::tie(code, err) = phyxel("run scene.json --steps -4");
  EXPECT_EQ(code, 2);
  EXPECT_NE(err.find("--steps"), std::string::npos) << err;
}

}  // namespace
}  // namespace phyxel
