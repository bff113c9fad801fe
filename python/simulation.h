// The C++ side of the Python module's Simulation (module.cpp binds it): a scene, its solver
// and the run loop (engine/run/run_loop.h) that `phyxel run` drives, advanced a number of
// steps at a time, with its state, tools, summary, frames and checkpoints on demand.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/run/run_loop.h"
#include "engine/surgery/resection.h"
#include "render/image.h"

namespace phyxel::render {
class FrameWriter;
}

namespace phyxel::python {

// The state failed (non-finite or running away): the message `phyxel run` prints.
class SimulationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct SimulationOptions {
  std::string device = "cpu";         // cpu, gpu, gpu:N or part of a device name (phyxel run)
  int threads = 0;                    // CPU threads, 0: all cores
  bool pass_selection = true;         // false: phyxel run --no-skip
  std::string render_device = "gpu";  // the renderer's Vulkan device with a CPU solver
};

// flags(): the set's PhyxelFlags (as in the .vtp files), kRemoved and kSurface also where an
// aspiration removed or exposed a phyxel, and this bit where a tool touched it in the last
// substep (the .vtp files' `contact` array).
inline constexpr uint32_t kContactFlag = 1u << 3;

class Simulation {
 public:
  // `resume`: a checkpoint file (phyxel run --checkpoint-every or save_checkpoint) to continue
  // from, or empty. Throws SceneError, CheckpointError, VulkanError or std::runtime_error.
  // `scene_hash`: the scene's identity in checkpoints (file_hash of its file; of its text for a
  // scene from a dict).
  Simulation(Scene scene, uint64_t scene_hash, const SimulationOptions& options,
             const std::filesystem::path& resume);
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  // Advances `steps` steps as `phyxel run --steps steps_done() + steps` resumed here would:
  // fewer when the scene comes to rest or `stop` (polled between advances) says so. Returns
  // the steps done; throws SimulationError when the state failed.
  int64_t advance(int64_t steps, const std::function<bool()>& stop);

  int64_t steps_done() const { return loop_->steps_done(); }
  double time() const { return double(steps_done()) * loop_->step_time(); }
  bool at_rest() const { return loop_->result().stopped_at_rest; }
  const Scene& scene() const { return scene_; }
  const PhyxelSet& set() const { return set_; }
  Solver& solver() { return *solver_; }
  const TimeStepPlan& plan() const { return loop_->result().plan; }

  PointState state(bool with_stress) { return solver_->read_state(with_stress); }
  std::vector<uint32_t> flags();
  size_t tool_index(const std::string& name) const;  // throws std::out_of_range naming it
  const ToolRunStats& tool_stats(size_t tool) { return loop_->tools().stats().at(tool); }
  const ToolPose& tool_pose(size_t tool) { return loop_->tools().poses().at(tool); }
  // From the next step on the tool leaves its path and moves to the pose over one step.
  void set_tool_pose(size_t tool, const Vec3& position, const Vec3& axis);
  nlohmann::json summary();
  Resection resection();
  // Of the pairs joining the phyxels of the inclusion `name` to other tissue, the fraction cut
  // (severed, or to a removed phyxel): 0 intact, 1 cut free all round. Throws
  // std::out_of_range naming the inclusions there are.
  double exposure(const std::string& name);
  // mode "mono" or "stereo" (side by side, both eyes); the frame is width x eye_count wide.
  render::RgbaImage render(const std::string& mode, int width, int height);
  void save_checkpoint(const std::filesystem::path& file);
  void write_points(const std::filesystem::path& file);

 private:
  Scene scene_;
  PhyxelSet set_;
  SimulationOptions options_;
  std::unique_ptr<Solver> solver_;
  std::unique_ptr<Checkpoint> resumed_;
  RunOptions run_options_;
  std::unique_ptr<RunLoop> loop_;
  std::function<bool()> stop_;
  std::vector<AspirationEvent> aspirations_;  // for frame writers made later
  std::vector<uint32_t> aspiration_flags_;    // kRemoved, kSurface an aspiration set
  struct Renderer;
  std::unique_ptr<Renderer> renderer_;
};

}  // namespace phyxel::python
