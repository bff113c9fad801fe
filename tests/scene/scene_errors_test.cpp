// Every invalid scene gives one SceneError line "FILE: JSON.PATH: problem; allowed ...".
// One test per case; each starts from the shipped demo (scenes/beam_tumour.json) and breaks one
// thing.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "engine/scene/scene.h"
#include "tests/scene/scene_error_helpers.h"
#include "tests/support/scoped_dir.h"

namespace phyxel {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

using namespace scene_test;

// --- files and syntax ---

TEST(SceneErrors, MissingFileNamesItAndSaysCheckThePath) {
  const fs::path file = fs::temp_directory_path() /
                        ("phyxel_no_such_dir_" + std::to_string(getpid())) / "missing.json";
  try {
    load_scene(file);
    ADD_FAILURE() << "no error";
  } catch (const SceneError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(file.string() + ": ", 0), 0u) << msg;
    EXPECT_NE(msg.find("check the path"), std::string::npos) << msg;
  }
}

TEST(SceneErrors, DirectoryInsteadOfFileIsUnreadable) {
  const test::ScopedDir scoped(fs::temp_directory_path() /
                               ("phyxel_scene_dir_" + std::to_string(getpid()) + ".json"));
  const fs::path& dir = scoped.path();
  try {
    load_scene(dir);
    ADD_FAILURE() << "no error";
  } catch (const SceneError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(dir.string() + ": ", 0), 0u) << msg;
    EXPECT_NE(msg.find("check the path"), std::string::npos) << msg;
  }
}

TEST(SceneErrors, SyntaxErrorGivesLineAndColumn) {
  const std::string msg = error_text("{\n  \"simulation\": {\"dt\": 1e-4,\n  \"steps\" 10}\n}");
  expect_error(msg, "simulation.steps", {"invalid JSON", "line 3", "column", "standard JSON"});
}

TEST(SceneErrors, TrailingCommaIsASyntaxError) {
  const std::string msg = error_text("{\"simulation\": {\"dt\": 1e-4,}}");
  expect_error(msg, "simulation.dt", {"line 1", "no trailing commas"});
}

TEST(SceneErrors, NumberOverflowIsNotFinite) {
  const std::string msg = error_text(
      R"({"simulation": {"dt": 1e-4, "steps": 1}, "objects": [{"material": {"young": 1e400}}]})");
  expect_error(msg, "objects[0].material.young", {"1e400", "not a finite number", "finite"});
}

TEST(SceneErrors, DuplicateKeyInOneObject) {
  const std::string msg = error_text(R"({"simulation": {"dt": 1e-4, "dt": 2e-4}})");
  expect_error(msg, "simulation.dt", {"duplicate key \"dt\"", "only once"});
}

TEST(SceneErrors, TopLevelMustBeAnObject) {
  expect_error(error_text("[1, 2]"), "(top level)",
               {"expected a scene object", "got an array of 2 elements", "simulation, objects"});
}

// --- unknown keys (typos) at every level ---

TEST(SceneErrors, UnknownTopLevelKeySuggestsTheRightOne) {
  const std::string msg = error_with([](json& j) { j["simulaton"] = json::object(); });
  expect_error(msg, "simulaton",
               {"unknown key \"simulaton\"", "did you mean \"simulation\"?",
                "allowed keys at the top level: simulation, objects, output"});
}

TEST(SceneErrors, UnknownSimulationKey) {
  const std::string msg = error_with([](json& j) { j["simulation"]["time_step"] = 1; });
  expect_error(msg, "simulation.time_step",
               {"unknown key", "dt, steps, gravity, until_rest, sleep, courant"});
}

TEST(SceneErrors, UnknownUntilRestKey) {
  const std::string msg = error_with([](json& j) { j["simulation"]["until_rest"]["steps"] = 5; });
  expect_error(msg, "simulation.until_rest.steps",
               {"unknown key", "kinetic_energy_below, for_steps"});
}

TEST(SceneErrors, UnknownObjectKey) {
  const std::string msg = error_with([](json& j) { object0(j)["spaceing"] = 0.01; });
  expect_error(msg, "objects[0].spaceing", {"did you mean \"spacing\"?", "in objects[0]:"});
}

TEST(SceneErrors, UnknownMaterialKey) {
  const std::string msg = error_with([](json& j) { material0(j)["yuong"] = 1e6; });
  expect_error(
      msg, "objects[0].material.yuong",
      {"did you mean \"young\"?", "young, poisson, density, damping, volume_stiffness, hourglass"});
}

TEST(SceneErrors, KeyOfAnotherShapeTypeIsUnknown) {
  const std::string msg = error_with([](json& j) { object0(j)["shape"]["radius"] = 0.1; });
  expect_error(msg, "objects[0].shape.radius",
               {"unknown key \"radius\"", "allowed keys in objects[0].shape: type, min, max"});
}

TEST(SceneErrors, UnknownInclusionKey) {
  const std::string msg = error_with([](json& j) { object0(j)["inclusions"][0]["materials"] = 1; });
  expect_error(msg, "objects[0].inclusions[0].materials",
               {"did you mean \"material\"?", "name, shape, material"});
}

TEST(SceneErrors, UnknownLoadKey) {
  const std::string msg = error_with([](json& j) { object0(j)["loads"][0]["forces"] = 1; });
  expect_error(msg, "objects[0].loads[0].forces", {"did you mean \"force\"?", "region, force"});
}

TEST(SceneErrors, UnknownOutputKey) {
  const std::string msg = error_with([](json& j) { j["output"]["interval"] = 10; });
  expect_error(msg, "output.interval", {"unknown key", "every, format"});
}

TEST(SceneErrors, UnknownShapeType) {
  const std::string msg = error_with([](json& j) { object0(j)["shape"]["type"] = "boxx"; });
  expect_error(msg, "objects[0].shape.type",
               {"unknown value \"boxx\"", "did you mean \"box\"?", "box, sphere, ellipsoid, mesh"});
}

TEST(SceneErrors, UnknownOutputFormat) {
  const std::string msg = error_with([](json& j) { j["output"]["format"] = "xml"; });
  expect_error(msg, "output.format", {"unknown value \"xml\"", "allowed ascii, binary"});
}

// --- wrong types ---

TEST(SceneErrors, StringWhereNumberExpected) {
  const std::string msg = error_with([](json& j) { object0(j)["spacing"] = "2.5mm"; });
  expect_error(msg, "objects[0].spacing",
               {"expected a number, got string \"2.5mm\"", "allowed spacing > 0 (m)"});
}

TEST(SceneErrors, ArrayOfWrongLength) {
  const std::string msg = error_with([](json& j) { j["simulation"]["gravity"] = {0, -9.81}; });
  expect_error(msg, "simulation.gravity",
               {"expected an array of 3 numbers, got an array of 2 elements", "[x, y, z]"});
}

TEST(SceneErrors, NonNumberInsideAVector) {
  const std::string msg = error_with([](json& j) { object0(j)["initial_velocity"][1] = true; });
  expect_error(msg, "objects[0].initial_velocity[1]", {"expected a number, got true"});
}

TEST(SceneErrors, FractionalStepCount) {
  const std::string msg = error_with([](json& j) { j["simulation"]["steps"] = 10.5; });
  expect_error(msg, "simulation.steps", {"10.5 is not a whole number", "steps >= 0"});
}

TEST(SceneErrors, StepCountTooLarge) {
  const std::string msg = error_with([](json& j) { j["simulation"]["steps"] = 1e30; });
  expect_error(msg, "simulation.steps", {"1e+30 is too large", "steps >= 0"});
}

TEST(SceneErrors, ObjectsMustBeAnArray) {
  const std::string msg = error_with([](json& j) { j["objects"] = object0(j); });
  expect_error(msg, "objects", {"expected an array of one or more objects, got an object"});
}

TEST(SceneErrors, MaterialMustBeAnObject) {
  const std::string msg = error_with([](json& j) { material0(j) = 1e6; });
  expect_error(msg, "objects[0].material",
               {"expected a material object", "got number 1000000", "young, poisson, density"});
}

TEST(SceneErrors, NameMustBeAString) {
  const std::string msg = error_with([](json& j) { object0(j)["name"] = 3; });
  expect_error(msg, "objects[0].name", {"expected a string, got number 3", "non-empty string"});
}

TEST(SceneErrors, EmptyName) {
  const std::string msg = error_with([](json& j) { object0(j)["name"] = ""; });
  expect_error(msg, "objects[0].name", {"empty string", "non-empty string"});
}

// --- required keys ---

TEST(SceneErrors, MissingDt) {
  const std::string msg = error_with([](json& j) { j["simulation"].erase("dt"); });
  expect_error(msg, "simulation.dt", {"missing required key \"dt\"", "dt > 0 (s)"});
}

TEST(SceneErrors, MissingSteps) {
  const std::string msg = error_with([](json& j) { j["simulation"].erase("steps"); });
  expect_error(msg, "simulation.steps", {"missing required key", "steps >= 0"});
}

TEST(SceneErrors, MissingSimulation) {
  const std::string msg = error_with([](json& j) { j.erase("simulation"); });
  expect_error(msg, "simulation", {"missing required key", "dt and steps"});
}

TEST(SceneErrors, MissingObjects) {
  const std::string msg = error_with([](json& j) { j.erase("objects"); });
  expect_error(msg, "objects", {"missing required key", "one or more objects"});
}

TEST(SceneErrors, EmptyObjects) {
  const std::string msg = error_with([](json& j) { j["objects"] = json::array(); });
  expect_error(msg, "objects", {"empty array", "one or more objects"});
}

TEST(SceneErrors, MissingName) {
  const std::string msg = error_with([](json& j) { object0(j).erase("name"); });
  expect_error(msg, "objects[0].name", {"missing required key", "non-empty string"});
}

TEST(SceneErrors, MissingShape) {
  const std::string msg = error_with([](json& j) { object0(j).erase("shape"); });
  expect_error(msg, "objects[0].shape", {"missing required key", "box", "mesh"});
}

TEST(SceneErrors, MissingSpacing) {
  const std::string msg = error_with([](json& j) { object0(j).erase("spacing"); });
  expect_error(msg, "objects[0].spacing", {"missing required key", "spacing > 0 (m)"});
}

TEST(SceneErrors, MissingYoung) {
  const std::string msg = error_with([](json& j) { material0(j).erase("young"); });
  expect_error(msg, "objects[0].material.young",
               {"missing required key", "0 < young <= 1000000000000 (Pa)"});
}

TEST(SceneErrors, MissingPoisson) {
  const std::string msg = error_with([](json& j) { material0(j).erase("poisson"); });
  expect_error(msg, "objects[0].material.poisson", {"missing required key", "-1 < poisson < 0.5"});
}

TEST(SceneErrors, MissingDensity) {
  const std::string msg = error_with([](json& j) { material0(j).erase("density"); });
  expect_error(msg, "objects[0].material.density", {"missing required key", "1 <= density"});
}

TEST(SceneErrors, InclusionMaterialNeedsYoung) {
  const std::string msg =
      error_with([](json& j) { object0(j)["inclusions"][0]["material"].erase("young"); });
  expect_error(msg, "objects[0].inclusions[0].material.young",
               {"missing required key", "0 < young <= 1000000000000 (Pa)"});
}

TEST(SceneErrors, MissingLoadForce) {
  const std::string msg = error_with([](json& j) { object0(j)["loads"][0].erase("force"); });
  expect_error(msg, "objects[0].loads[0].force", {"missing required key", "[x, y, z]", "(N)"});
}

TEST(SceneErrors, DuplicateObjectName) {
  const std::string msg = error_with([](json& j) { j["objects"].push_back(object0(j)); });
  expect_error(msg, "objects[1].name",
               {"duplicate object name \"beam\"", "also objects[0].name", "no other object"});
}

TEST(SceneErrors, DuplicateInclusionName) {
  const std::string msg =
      error_with([](json& j) { object0(j)["inclusions"].push_back(object0(j)["inclusions"][0]); });
  expect_error(msg, "objects[0].inclusions[1].name",
               {"duplicate inclusion name \"tumour\"", "no other inclusion"});
}

}  // namespace
}  // namespace phyxel
