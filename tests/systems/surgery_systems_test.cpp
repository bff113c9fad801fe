// The paper's two surgery systems end to end on the CPU, run by the command line as a user
// runs them (issue #33 item 8): the brain tumour removal, coarsened from 2 mm to 3 mm for CI's
// time (its path, materials and tearing as shipped), and the breast resection as shipped. Each
// takes one to two minutes on one core; their outcomes are read from summary.json. The figures
// in the comments are of the CPU on the device machine (docs/suction.md, docs/cutting.md).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "tests/physics/physics_fixtures.h"

namespace phyxel {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

json read_json(const fs::path& p) {
  std::ifstream in(p);
  return json::parse(in);
}

// Runs `scene` on the CPU (one thread, no frames) into `dir`; returns its summary.json.
json run_scene(const fs::path& scene, const fs::path& dir) {
  const std::string command = std::string(PHYXEL_BINARY_DIR) + "/app/phyxel run " + scene.string() +
                              " --device cpu --render none --threads 1 --quiet" + " --out " +
                              dir.string() + " > " + (dir / "log.txt").string() + " 2>&1";
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  if (!fs::exists(dir / "summary.json")) return json::object();
  return read_json(dir / "summary.json");
}

const json& named(const json& list, const std::string& name) {
  for (const json& item : list)
    if (item.value("name", "") == name) return item;
  ADD_FAILURE() << "no \"" << name << "\" in " << list.dump();
  static const json none = json::object();
  return none;
}

// The brain at 3 mm (the scene's dt scaled with the spacing; its steps to the path's end), the
// render keys dropped (they name files beside the shipped scene).
fs::path coarse_brain(const fs::path& dir) {
  json s = read_json(fs::path(PHYXEL_SOURCE_DIR) / "scenes/brain_tumour_removal.json");
  const double spacing = 0.003, dt = 2.4e-4;
  s["objects"][0]["spacing"] = spacing;
  s["simulation"]["dt"] = dt;
  const double end = s["tools"][0]["path"].back()["t"].get<double>();
  s["simulation"]["steps"] = int(end / dt);
  s.erase("render");
  const fs::path file = dir / "brain_3mm.json";
  std::ofstream(file) << s.dump(1);
  return file;
}

// The aspirator works through the glioma layer by layer: most of it is aspirated (88.5 % at
// 3 mm; 96.9 % at the shipped 2 mm on the GPU), piece by piece, with a margin of brain
// (1.92 g, 1.2 %; 2.16 g, 1.3 % at 2 mm), no crater.
TEST(SurgerySystems, BrainTumourRemovalAspiratesTheGlioma) {
  const fs::path dir = test::test_output_dir("systems_brain");
  const json s = run_scene(coarse_brain(dir), dir);
  ASSERT_TRUE(s.contains("aspiration")) << s.dump();
  EXPECT_FALSE(s["non_finite"].get<bool>());
  const json& parts = s["aspiration"]["parts"];
  const json& glioma = named(parts, "glioma");
  const json& brain = named(parts, "brain");
  EXPECT_GE(glioma.value("removed_percent", 0.0), 80.0) << parts.dump();
  EXPECT_LE(brain.value("removed_g", 1e9), 2.4) << parts.dump();
  EXPECT_LE(brain.value("removed_percent", 1e9), 1.5) << parts.dump();
  EXPECT_GE(s["aspiration"]["events"].get<int>(), 40);
  // Aspirated piecemeal: what is left of the glioma is not one freed piece.
  const json& cut = named(s["cutting"]["inclusions"], "glioma");
  EXPECT_FALSE(cut.value("whole", true)) << cut.dump();
}

// The scalpel's cutting force per step (tools.csv's cut_force column), in step order.
std::vector<double> scalpel_cut_forces(const fs::path& tools_csv) {
  std::ifstream in(tools_csv);
  std::string line;
  std::getline(in, line);  // the header: step,t,name,...,contacts,cut_force,...
  std::vector<double> force;
  while (std::getline(in, line)) {
    std::vector<std::string> cell;
    std::stringstream row(line);
    for (std::string c; std::getline(row, c, ',');) cell.push_back(c);
    if (cell.size() > 13 && cell[2] == "scalpel") force.push_back(std::stod(cell[13]));
  }
  return force;
}

// The scalpel cuts a cone around the carcinoma and the tenaculum lifts it out whole with a
// rim of healthy tissue (22.7 g), in a few freed pieces (10); the cutting force reaches the
// blade's threshold (0.1 N) and the tenaculum lifts a freed piece (1.1 N), not the breast (47 N
// when the cone does not close). The tissue deforms before it separates: the point's force rises
// through 20-80 % of the threshold over tens of steps (the skin pressed in) before the rupture.
TEST(SurgerySystems, BreastResectionRemovesTheCarcinomaWhole) {
  const fs::path scene = fs::path(PHYXEL_SOURCE_DIR) / "scenes/breast_resection.json";
  const fs::path dir = test::test_output_dir("systems_breast");
  const json s = run_scene(scene, dir);
  ASSERT_TRUE(s.contains("cutting")) << s.dump();
  EXPECT_FALSE(s["non_finite"].get<bool>());
  const json& carcinoma = named(s["cutting"]["inclusions"], "carcinoma");
  EXPECT_GE(carcinoma.value("removed_percent", 0.0), 99.9) << carcinoma.dump();
  EXPECT_TRUE(carcinoma.value("whole", false)) << carcinoma.dump();
  EXPECT_GT(carcinoma.value("healthy_removed_g", 0.0), 10.0) << carcinoma.dump();
  EXPECT_LT(carcinoma.value("healthy_removed_g", 1e9), 35.0) << carcinoma.dump();
  const int pieces = s["cutting"]["freed_pieces"].get<int>();
  EXPECT_GE(pieces, 1);
  EXPECT_LE(pieces, 20);
  const double threshold =
      read_json(scene)["tools"][0].value("cut_force_threshold", 0.0);  // the scalpel's
  const json& scalpel = named(s["tools"], "scalpel");
  EXPECT_GE(scalpel.value("max_cut_force", 0.0), threshold) << scalpel.dump();
  EXPECT_GT(scalpel.value("cutting_substeps", 0), 0) << scalpel.dump();
  EXPECT_LT(named(s["tools"], "tenaculum").value("max_force", 1e9), 5.0);
  EXPECT_GT(threshold, 0.0);  // the paper's rule is on
  const std::vector<double> force = scalpel_cut_forces(dir / "tools.csv");
  size_t rising = 0, k = 0;
  for (; k < force.size() && force[k] < 0.8 * threshold; ++k) rising += force[k] > 0.2 * threshold;
  ASSERT_LT(k, force.size()) << "the force never neared the threshold";
  EXPECT_GE(rising, 10u) << "the force jumped to the threshold at step " << k + 1;
}

}  // namespace
}  // namespace phyxel
