// The values of a checkpoint whose checksum holds, checked against the scene before a resumed
// run uses them: a file edited by hand (or by a program) and given a new checksum must be
// refused with a CheckpointError, never reach the solver (indices out of range) or the outputs
// (names that are not the scene's, non-finite numbers).
#pragma once

#include <filesystem>

#include "engine/run/checkpoint.h"
#include "engine/scene/scene.h"

namespace phyxel {

// Throws CheckpointError naming `file` and the first value out of place.
void check_checkpoint_values(const Checkpoint& c, const std::filesystem::path& file,
                             const Scene& scene, const PhyxelSet& set);

}  // namespace phyxel
