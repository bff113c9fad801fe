// Helpers of the checkpoint tests (checkpoint_test.cpp, checkpoint_sections_test.cpp): `phyxel
// run` as a child, scenes written to files, the test GPU's arguments, a scalpel scene.
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include "compute/test_env.h"
#include "engine/run/checkpoint_format.h"
#include "tests/support/support.h"

namespace phyxel::checkpoint_test {

using test::exit_status;
using test::kPhyxel;
using test::read_text;

namespace fs = std::filesystem;

inline void write_bytes(const fs::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary) << bytes;
}

struct Ran {
  int code;
  std::string err;
};
// `phyxel run SCENE ARGS --quiet` under `timeout`, stderr kept.
inline Ran run(const fs::path& scene, const std::string& args, const fs::path& dir) {
  const fs::path err = dir / "stderr.txt";
  const std::string command = "timeout 300 " + kPhyxel + " run " + scene.string() + " " + args +
                              " --quiet >/dev/null 2>" + err.string();
  const int status = std::system(command.c_str());
  return {exit_status(status), read_text(err)};
}

// A scalpel cutting a slit through a small block (docs/cutting.md): cuts happen before and
// after the checkpoints; its threshold makes it hold pairs and keep sides.
constexpr const char* kScalpel = R"({
  "simulation": {"dt": 2e-4, "steps": 200, "gravity": [0, 0, -9.81]},
  "objects": [{"name": "block", "shape": {"type": "box", "min": [0, 0, 0], "max": [0.02, 0.012, 0.01]},
    "spacing": 0.002,
    "material": {"young": 5e3, "poisson": 0.3, "density": 1000, "damping": 10},
    "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.0005]}]}],
  "output": {"every": 50, "format": "binary"},
  "tools": [{"name": "scalpel", "type": "scalpel",
     "shape": {"type": "capsule", "radius": 0.0003, "length": 0.02},
     "blade": {"length": 0.015, "edge": [1, 0, 0]}, "friction": 0.3, "cut_force_threshold": 0.001,
     "path": [{"t": 0, "position": [-0.002, 0.0061, 0.004]}, {"t": 0.04, "position": [0.022, 0.0061, 0.004]}]}]
})";

inline fs::path write_scene(const fs::path& dir, const std::string& name, const std::string& json) {
  fs::create_directories(dir);
  const fs::path file = dir / name;
  std::ofstream(file) << json;
  return file;
}

// The command-line arguments that run the test GPU ("--device NAME", with " --validate" where
// validation is on; lavapipe: sets VK_DRIVER_FILES for the child), or nothing and `why` when
// there is no Vulkan device.
inline std::optional<std::string> gpu_device_args(std::string& why) {
  try {
    const gpu::ContextOptions context = gpu::test_context_options();
    return "--device " + context.device + (context.validation ? " --validate" : "");
  } catch (const VulkanError& e) {
    why = e.what();
    return std::nullopt;
  }
}

}  // namespace phyxel::checkpoint_test
