// Validation cases with references that no part of Phyxel computed: the cantilever, whole and
// with a slit cut at rest, against CalculiX, the uniaxial stretch and the bar wave speed against
// closed-form answers. Shared by the tests (tests/validation) and `phyxel bench --accuracy`, which
// sweeps resolution, time step and device.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "engine/solver/solver.h"

namespace phyxel {

struct ValidationCase {
  std::string name;  // cantilever_small, cantilever_large, cantilever_slit, uniaxial_bar, wave_bar
  std::filesystem::path scene;  // scenes/validation/<name>.json
  std::string quantity;         // what is measured
  double reference = 0;         // its reference value
  std::string reference_source;
};

// The cases, with references read from scenes/validation/ (CalculiX results) or derived from
// the scene's material (closed form). `source_dir` is the repository root.
std::vector<ValidationCase> validation_cases(const std::filesystem::path& source_dir);

struct ValidationRun {
  std::string case_name, device;
  double spacing = 0, dt = 0, dt_fraction = 0;  // dt = dt_fraction * stable bound
  size_t phyxels = 0;
  int64_t steps = 0;
  double wall_seconds = 0;
  double value = 0, reference = 0;
  double error = 0;      // relative; for the uniaxial bar the larger of the E and nu errors
  double secondary = 0;  // cantilevers: tip u_x (m); uniaxial bar: Poisson ratio
  bool finite = true;
};

using SolverFactory = std::function<std::unique_ptr<Solver>(const PhyxelSet&, const Vec3&)>;

// Runs one case with the scene's spacing times `spacing_scale` (the support radius follows)
// and a step of `dt_fraction` of the stable bound.
ValidationRun run_validation(const ValidationCase& c, double spacing_scale, double dt_fraction,
                             const SolverFactory& make_solver);

}  // namespace phyxel
