// DIR/checkpoint.phx: everything `phyxel run --resume DIR` needs to continue a run exactly
// where it stopped (docs/checkpoint.md has the byte layout). No Vulkan here: the run loop fills
// a Checkpoint from the Solver interface and restores it through it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/sampling/phyxel_set.h"
#include "engine/solver/cut_band_state.h"
#include "engine/solver/cutting.h"
#include "engine/solver/grasper.h"
#include "engine/surgery/aspiration.h"
#include "engine/surgery/tool_track.h"

namespace phyxel {

// One line naming the file and what is wrong with it (missing, truncated, checksum, version,
// another scene or device).
class CheckpointError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline constexpr char kCheckpointMagic[8] = {'P', 'H', 'X', 'C', 'K', 'P', 'T', '1'};
inline constexpr uint32_t kCheckpointVersion = 1;
inline constexpr const char* kCheckpointFile = "checkpoint.phx";

struct Checkpoint {
  // Identity: what the checkpoint may be resumed with.
  uint64_t scene_hash = 0;  // FNV-1a 64 of the scene file's bytes
  uint64_t set_hash = 0;    // FNV-1a 64 of the sampled set's count and rest positions
  std::string solver;       // solver_identity(device()): "cpu (double)", "gpu:0 ... (float32)"
  std::string device;       // the full device() string, for messages
  // Time.
  int64_t step = 0;  // steps done
  double time = 0;   // step * dt_requested, s
  double dt_requested = 0;
  int64_t substeps = 1;
  int64_t check_every = 0;       // the run loop's check interval
  int64_t checkpoint_every = 0;  // N of --checkpoint-every
  int64_t total = 0;             // the steps the checkpointed run was asked for
  // State, double (float solvers' values converted exactly).
  std::vector<Vec3> displacement, velocity;
  // Sleep: per object awake (0/1) and the step since which its kinetic energy stayed below
  // the sleep threshold (-1: not below).
  std::vector<uint8_t> awake;
  std::vector<int64_t> object_below_since;
  // Load schedule: load switch events applied so far.
  int64_t loads_applied = 0;
  // The run loop's checks: until_rest's below-since step, event counters, and the
  // displacement as of the last check (with tools: where sleeping objects are tested).
  int64_t rest_below_since = -1;
  int64_t sleeps = 0, wakes = 0, load_changes = 0;
  // Each sleeping object's u when it went to sleep (the others' entries are not read); empty
  // without tools.
  std::vector<Vec3> last_check_u;
  // Tools: the pose each ended the last chunk at and its statistics so far.
  std::vector<ToolPose> tool_poses;
  std::vector<ToolRunStats> tool_stats;
  // Topology: the per-phyxel flags (PhyxelFlags, kRemoved for removed phyxels) and the pairs
  // cut so far (the solver's log, in its order; resumed through Solver::sever_pairs).
  std::vector<uint32_t> flags;
  std::vector<SeveredPair> severed;
  // The graspers' grips, one per tool (empty without a grasper), and the aspirator's state
  // (its surface empty without one).
  std::vector<Grip> grips;
  AspiratorState aspiration;
  // The SCNI band round the cuts (objects with cut_band; empty without one).
  CutBandState band;
  // Per tool, the sides its blade keeps (engine/solver/cutting.h, BladeSide; empty without a
  // blade or in a checkpoint written before them or before their normals: none kept).
  std::vector<std::vector<BladeSide>> blade_sides;
  // Per tool, 1 where its blade is in the cutting state (docs/cutting.md, "Rupture and the cutting
  // state"); empty in a checkpoint written before it: every blade starts uncut, needing its
  // threshold again.
  std::vector<uint8_t> blades_cutting;
};

// FNV-1a 64 over bytes, continuing from `h`.
uint64_t fnv1a64(const void* data, size_t size, uint64_t h = 0xcbf29ce484222325ull);
// Of the file's bytes; throws CheckpointError when it cannot be read.
uint64_t file_hash(const std::filesystem::path& file);
// Of the set's phyxel count and rest positions.
uint64_t phyxel_set_hash(const PhyxelSet& set);
// What results depend on in a device() string: the CPU's thread count does not (its sums
// have a fixed order), so "cpu (double, 2 threads)" -> "cpu (double)"; a GPU's name stays.
std::string solver_identity(const std::string& device);

// Writes `file` atomically: a temporary file in the same folder, flushed to disk (fsync), then
// renamed over `file`; on failure the temporary is removed. Throws CheckpointError.
void write_checkpoint(const std::filesystem::path& file, const Checkpoint& checkpoint);
// Reads and verifies (length, checksum, magic, version) `file`. Throws CheckpointError.
Checkpoint read_checkpoint(const std::filesystem::path& file);
// The checkpoint in `bytes` (a file's content; `name` for messages). Throws CheckpointError.
Checkpoint parse_checkpoint(const std::string& bytes, const std::string& name);
// Throws CheckpointError unless `checkpoint` (read from `file`) belongs to this scene file,
// this sampled set and this solver.
void check_checkpoint_matches(const Checkpoint& checkpoint, const std::filesystem::path& file,
                              uint64_t scene_hash, const PhyxelSet& set, const std::string& device);

}  // namespace phyxel
