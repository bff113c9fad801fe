// Scene files that must parse: the demo from the issue, defaults, every shipped scene.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "engine/geometry/mesh.h"
#include "engine/scene/scene.h"
#include "tests/support/scoped_dir.h"

namespace phyxel {
namespace {

namespace fs = std::filesystem;

const fs::path kSource = PHYXEL_SOURCE_DIR;

constexpr const char* kDemo = R"({
  "simulation": {"dt": 5e-5, "steps": 20000, "gravity": [0, 0, -9.81],
                 "until_rest": {"kinetic_energy_below": 1e-10, "for_steps": 1000}, "courant": 0.5},
  "objects": [{
    "name": "beam",
    "shape": {"type": "box", "min": [0, -0.01, -0.01], "max": [0.1, 0.01, 0.01]},
    "spacing": 0.0025,
    "support_radius": 0.005,
    "material": {"young": 1e6, "poisson": 0.3, "density": 1000, "damping": 2.0,
                 "volume_stiffness": 1e5, "hourglass": 0.05},
    "inclusions": [{"name": "tumour", "shape": {"type": "sphere", "center": [0.05,0,0], "radius": 0.005},
                    "material": {"young": 1e7, "poisson": 0.4, "density": 1100}}],
    "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [0.0005, 1, 1]}],
    "loads": [{"region": {"type": "box", "min": [0.0995,-1,-1], "max": [1,1,1]}, "force": [0,0,-0.1]}],
    "initial_velocity": [0, 0, 0]
  }],
  "output": {"every": 0, "format": "ascii"}
})";

// The smallest valid scene: only the required keys.
constexpr const char* kMinimal = R"({
  "simulation": {"dt": 1e-4, "steps": 10},
  "objects": [{"name": "block", "shape": {"type": "box", "min": [0, 0, 0], "max": [0.01, 0.01, 0.01]},
               "spacing": 0.002, "material": {"young": 1000, "poisson": 0.3, "density": 1000}}]
})";

TEST(SceneParse, DemoSceneHasTheGivenValues) {
  const Scene s = parse_scene(kDemo, "demo.json");
  EXPECT_EQ(s.file, fs::path("demo.json"));
  EXPECT_DOUBLE_EQ(s.simulation.dt, 5e-5);
  EXPECT_EQ(s.simulation.steps, 20000);
  EXPECT_EQ(s.simulation.gravity, Vec3(0, 0, -9.81));
  EXPECT_TRUE(s.simulation.until_rest.enabled);
  EXPECT_DOUBLE_EQ(s.simulation.until_rest.kinetic_energy_below, 1e-10);
  EXPECT_EQ(s.simulation.until_rest.for_steps, 1000);
  EXPECT_DOUBLE_EQ(s.simulation.courant, 0.5);
  ASSERT_EQ(s.objects.size(), 1u);
  const ObjectDesc& o = s.objects[0];
  EXPECT_EQ(o.name, "beam");
  EXPECT_EQ(o.shape.type, Shape::Type::Box);
  EXPECT_EQ(o.shape.min, Vec3(0, -0.01, -0.01));
  EXPECT_EQ(o.shape.max, Vec3(0.1, 0.01, 0.01));
  EXPECT_DOUBLE_EQ(o.spacing, 0.0025);
  EXPECT_DOUBLE_EQ(o.support_radius, 0.005);
  EXPECT_DOUBLE_EQ(o.material.young, 1e6);
  EXPECT_DOUBLE_EQ(o.material.poisson, 0.3);
  EXPECT_DOUBLE_EQ(o.material.density, 1000);
  EXPECT_DOUBLE_EQ(o.material.damping, 2.0);
  ASSERT_TRUE(o.material.volume_stiffness.has_value());
  EXPECT_DOUBLE_EQ(*o.material.volume_stiffness, 1e5);
  EXPECT_DOUBLE_EQ(o.material.hourglass, 0.05);
  ASSERT_EQ(o.inclusions.size(), 1u);
  EXPECT_EQ(o.inclusions[0].name, "tumour");
  EXPECT_EQ(o.inclusions[0].shape.type, Shape::Type::Sphere);
  EXPECT_EQ(o.inclusions[0].shape.center, Vec3(0.05, 0, 0));
  EXPECT_DOUBLE_EQ(o.inclusions[0].shape.radius, 0.005);
  EXPECT_DOUBLE_EQ(o.inclusions[0].material.young, 1e7);
  EXPECT_DOUBLE_EQ(o.inclusions[0].material.poisson, 0.4);
  EXPECT_DOUBLE_EQ(o.inclusions[0].material.density, 1100);
  ASSERT_EQ(o.fixed.size(), 1u);
  EXPECT_EQ(o.fixed[0].max, Vec3(0.0005, 1, 1));
  ASSERT_EQ(o.loads.size(), 1u);
  EXPECT_EQ(o.loads[0].region.min, Vec3(0.0995, -1, -1));
  EXPECT_EQ(o.loads[0].force, Vec3(0, 0, -0.1));
  EXPECT_EQ(o.initial_velocity, Vec3::Zero());
  EXPECT_EQ(s.output.every, 0);
  EXPECT_FALSE(s.output.binary);
}

TEST(SceneParse, MinimalSceneGetsTheDocumentedDefaults) {
  const Scene s = parse_scene(kMinimal, "minimal.json");
  EXPECT_EQ(s.simulation.gravity, Vec3::Zero());
  EXPECT_FALSE(s.simulation.until_rest.enabled);
  EXPECT_DOUBLE_EQ(s.simulation.courant, 0.5);
  const ObjectDesc& o = s.objects.at(0);
  EXPECT_DOUBLE_EQ(o.support_radius, 2 * 0.002);
  EXPECT_DOUBLE_EQ(o.material.damping, 0);
  EXPECT_DOUBLE_EQ(o.material.hourglass, 0.05);
  EXPECT_FALSE(o.material.volume_stiffness.has_value());
  EXPECT_TRUE(o.inclusions.empty());
  EXPECT_TRUE(o.fixed.empty());
  EXPECT_TRUE(o.loads.empty());
  EXPECT_EQ(o.initial_velocity, Vec3::Zero());
  EXPECT_EQ(s.output.every, 0);
  EXPECT_FALSE(s.output.binary);
}

TEST(SceneParse, UntilRestForStepsDefaultsTo1000) {
  auto j = nlohmann::json::parse(kMinimal);
  j["simulation"]["until_rest"] = {{"kinetic_energy_below", 1e-6}};
  const Scene s = parse_scene(j.dump(), "rest.json");
  EXPECT_TRUE(s.simulation.until_rest.enabled);
  EXPECT_DOUBLE_EQ(s.simulation.until_rest.kinetic_energy_below, 1e-6);
  EXPECT_EQ(s.simulation.until_rest.for_steps, 1000);
}

TEST(SceneParse, InclusionMaterialInheritsHostDampingHourglassAndVolumeStiffness) {
  auto j = nlohmann::json::parse(kDemo);
  j["objects"][0]["material"]["hourglass"] = 0.2;
  const Scene s = parse_scene(j.dump(), "demo.json");
  const Material& m = s.objects[0].inclusions[0].material;
  EXPECT_DOUBLE_EQ(m.damping, 2.0);
  EXPECT_DOUBLE_EQ(m.hourglass, 0.2);
  ASSERT_TRUE(m.volume_stiffness.has_value());
  EXPECT_DOUBLE_EQ(*m.volume_stiffness, 1e5);
}

TEST(SceneParse, InclusionMaterialOverridesHostValues) {
  auto j = nlohmann::json::parse(kDemo);
  j["objects"][0]["inclusions"][0]["material"]["damping"] = 7;
  j["objects"][0]["inclusions"][0]["material"]["volume_stiffness"] = 0;
  const Scene s = parse_scene(j.dump(), "demo.json");
  const Material& m = s.objects[0].inclusions[0].material;
  EXPECT_DOUBLE_EQ(m.damping, 7);
  ASSERT_TRUE(m.volume_stiffness.has_value());
  EXPECT_DOUBLE_EQ(*m.volume_stiffness, 0);
}

TEST(SceneParse, UnnamedInclusionsGetNumberedNames) {
  auto j = nlohmann::json::parse(kDemo);
  j["objects"][0]["inclusions"][0].erase("name");
  EXPECT_EQ(parse_scene(j.dump(), "demo.json").objects[0].inclusions[0].name, "inclusion0");
}

TEST(SceneParse, EllipsoidAndBinaryOutput) {
  auto j = nlohmann::json::parse(kMinimal);
  j["objects"][0]["shape"] = {
      {"type", "ellipsoid"}, {"center", {1, 2, 3}}, {"radii", {0.1, 0.2, 0.3}}};
  j["output"] = {{"every", 50}, {"format", "binary"}};
  const Scene s = parse_scene(j.dump(), "e.json");
  EXPECT_EQ(s.objects[0].shape.type, Shape::Type::Ellipsoid);
  EXPECT_EQ(s.objects[0].shape.center, Vec3(1, 2, 3));
  EXPECT_EQ(s.objects[0].shape.radii, Vec3(0.1, 0.2, 0.3));
  EXPECT_EQ(s.output.every, 50);
  EXPECT_TRUE(s.output.binary);
}

TEST(SceneParse, WholeNumberWrittenWithExponentIsAnInteger) {
  auto j = nlohmann::json::parse(kMinimal);
  j["simulation"]["steps"] = 2e4;
  EXPECT_EQ(parse_scene(j.dump(), "s.json").simulation.steps, 20000);
}

TEST(SceneParse, SupportRadiusJustAboveSqrt2SpacingIsAccepted) {
  auto j = nlohmann::json::parse(kMinimal);
  j["objects"][0]["support_radius"] = 1.4143 * 0.002;
  EXPECT_DOUBLE_EQ(parse_scene(j.dump(), "s.json").objects[0].support_radius, 1.4143 * 0.002);
}

TEST(SceneParse, LoadSceneReadsTheFileAndRemembersItsPath) {
  const test::ScopedDir dir(fs::temp_directory_path() /
                            ("phyxel_scene_parse_test_" + std::to_string(getpid())));
  const fs::path file = dir.path() / "minimal.json";
  std::ofstream(file) << kMinimal;
  const Scene s = load_scene(file);
  EXPECT_EQ(s.file, file);
  EXPECT_EQ(s.objects.at(0).name, "block");
}

TEST(SceneParse, MeshPathIsResolvedAgainstTheSceneFolderAndScaled) {
  const fs::path file = kSource / "tests/data/scenes/mesh_cube.json";
  const Scene s = load_scene(file);
  const Shape& shape = s.objects.at(0).shape;
  EXPECT_EQ(shape.type, Shape::Type::Mesh);
  EXPECT_EQ(shape.path, kSource / "tests/data/scenes/cube.obj");
  EXPECT_DOUBLE_EQ(shape.scale, 0.02);
  ASSERT_NE(shape.mesh, nullptr);
  EXPECT_NEAR(shape.mesh->bounds.max().x(), 0.02, 1e-12);
}

TEST(SceneParse, ShippedBeamSceneIsTheIssueDemoWithFewerSteps) {
  // The demo scene of the foundation issue, word for word but for the step count.
  const char* issue_demo = R"({
    "simulation": {"dt": 5e-5, "steps": 20000, "gravity": [0, 0, -9.81],
                   "until_rest": {"kinetic_energy_below": 1e-10}},
    "objects": [{
      "name": "beam",
      "shape": {"type": "box", "min": [0, -0.01, -0.01], "max": [0.1, 0.01, 0.01]},
      "spacing": 0.0025,
      "material": {"young": 1e6, "poisson": 0.3, "density": 1000, "damping": 2.0},
      "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [0.0005, 1, 1]}]
    }],
    "output": {"every": 0}
  })";
  auto demo = nlohmann::json::parse(issue_demo);
  demo["simulation"]["steps"] = 4000;
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(kSource / "scenes/beam.json")), demo);
  const Scene s = load_scene(kSource / "scenes/beam.json");
  EXPECT_EQ(s.simulation.steps, 4000);
  EXPECT_DOUBLE_EQ(s.objects[0].support_radius, 0.005);  // default 2 * spacing
}

TEST(SceneParse, ShippedTumourBeamSpellsOutEveryKey) {
  auto demo = nlohmann::json::parse(kDemo);
  demo["simulation"]["steps"] = 4000;
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(kSource / "scenes/beam_tumour.json")), demo);
  EXPECT_EQ(load_scene(kSource / "scenes/beam_tumour.json").simulation.steps, 4000);
}

// Stable step estimate of the solver: courant * spacing / fastest p-wave speed.
double stable_dt(const Scene& s) {
  double dt = 1e30;
  for (const ObjectDesc& o : s.objects) {
    dt = std::min(dt, s.simulation.courant * o.spacing / p_wave_speed(o.material));
    for (const Inclusion& inc : o.inclusions) {
      dt = std::min(dt, s.simulation.courant * o.spacing / p_wave_speed(inc.material));
    }
  }
  return dt;
}

TEST(SceneParse, SurgeryScenesUseAStableStepWithoutSubstepping) {
  for (const char* name : {"scenes/brain_tumour.json", "scenes/breast_tumour.json"}) {
    const Scene s = load_scene(kSource / name);
    EXPECT_LE(s.simulation.dt, stable_dt(s)) << name;
    EXPECT_GE(s.simulation.dt, 0.8 * stable_dt(s)) << name;
    ASSERT_EQ(s.objects.size(), 1u) << name;
    EXPECT_EQ(s.objects[0].inclusions.size(), 1u) << name;
    EXPECT_FALSE(s.objects[0].fixed.empty()) << name;
    EXPECT_GT(s.objects[0].inclusions[0].material.young, s.objects[0].material.young) << name;
  }
}

TEST(SceneParse, EveryShippedSceneParses) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(kSource / "scenes")) {
    if (entry.path().extension() != ".json") continue;
    try {
      load_scene(entry.path());
    } catch (const SceneError& e) {
      ADD_FAILURE() << e.what();
    }
    ++count;
  }
  EXPECT_GE(count, 3);
}

}  // namespace
}  // namespace phyxel
