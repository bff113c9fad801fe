// VTK XML PolyData point files (.vtp) that ParaView opens: points at their deformed
// positions, one vertex cell per point, and the point arrays rest_position, displacement,
// velocity, von_mises and flags; max_principal_stress when the state has it (a scene that can
// tear) and contact when it has that (a scene with tools).
#pragma once

#include <filesystem>

#include "engine/solver/solver.h"

namespace phyxel {

// Writes atomically (a temporary file renamed into place), so an interrupted run never leaves
// a half-written file. `binary`: raw appended data instead of ASCII. Throws std::runtime_error
// naming the file when it cannot be written.
void write_points_vtp(const std::filesystem::path& file, const PhyxelSet& set,
                      const PointState& state, bool binary);

}  // namespace phyxel
