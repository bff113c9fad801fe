// The grasper's test scene, shared by the CPU tests (tests/surgery/grasper_test.cpp) and the GPU
// parity test (tests/gpu_solver/grasper_test.cpp).
#pragma once

#include <sstream>
#include <string>

namespace phyxel::test {

constexpr double kBarLength = 0.03;  // m: bar_json's bar along x from 0

// A 3 cm x 4 mm x 4 mm bar (E = 10 kPa, nu = 0: uniaxial stress; spacing 1 mm, damping 100/s),
// fixed at x <= 1.5 mm, and a grasper (a 0.5 mm ball) whose tip is `tip_x` along the bar's
// axis. Its jaws close at 2 ms with `reach` and open at `until` (never when <= 0); from 5 ms to
// 55 ms it moves by `pull` in x, its axis turning from z to `end_axis`. Runs `seconds`.
inline std::string bar_json(double tip_x, double reach, double pull, double until, double seconds,
                            const std::string& end_axis = "[0, 0, 1]") {
  std::ostringstream j;
  j << R"({"simulation": {"dt": 1e-3, "steps": )" << int(seconds * 1000 + 0.5) << R"(,
    "gravity": [0, 0, 0]},
  "objects": [{"name": "bar", "shape": {"type": "box", "min": [0, -0.002, -0.002],
                                        "max": [0.03, 0.002, 0.002]},
    "spacing": 0.001,
    "material": {"young": 1e4, "poisson": 0, "density": 1000, "damping": 100},
    "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [0.0015, 1, 1]}]}],
  "tools": [{"name": "jaws", "type": "grasper", "shape": {"type": "sphere", "radius": 0.0005},
    "grasp": {"reach": )"
    << reach << R"(, "from": 0.002)" << (until > 0 ? ", \"until\": " + std::to_string(until) : "")
    << R"(},
    "path": [{"t": 0, "position": [)"
    << tip_x << R"(, 0, 0]}, {"t": 0.005, "position": [)" << tip_x
    << R"(, 0, 0]}, {"t": 0.055, "position": [)" << tip_x + pull << R"(, 0, 0], "axis": )"
    << end_axis << R"(}]}],
  "output": {"every": 0}})";
  return j.str();
}

}  // namespace phyxel::test
