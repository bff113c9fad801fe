// Private to the scene reader: limits checked on a whole scene once its parts are read, before
// anything is sampled or allocated, each failure one line naming the key and the limit.
#pragma once

#include "engine/scene/json_reader.h"
#include "engine/scene/scene.h"

namespace phyxel {

// A step split into more substeps than this is refused: at a microsecond per substep and
// phyxel, even a small scene would take minutes of wall time per simulated step.
constexpr double kMaxSubstepsPerStep = 1e6;
// A tool larger than this many times the scene's extent (the objects' bounds) is a unit slip
// (mm for m), not an instrument.
constexpr double kMaxToolToScene = 10;

// simulation.dt against the stable step of the stiffest material of each object (courant x
// spacing / p-wave speed): refused when a step needs more than kMaxSubstepsPerStep substeps.
void check_time_step(const json_reader::Node& root, const Scene& scene);
// Every tool's radius and capsule length against the scene's extent.
void check_tool_sizes(const json_reader::Node& root, const Scene& scene);

}  // namespace phyxel
