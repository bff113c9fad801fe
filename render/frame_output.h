// Headless frames of a run: DIR/frame_NNNNNN.png (NNNNNN the step) rendered from an offscreen
// image, with the scene's camera and render settings. Never needs a display.
//
//   FrameWriter     the renderer of one scene: surfel table, texture (the scene's
//                   render.texture or the procedural tissue texture), camera, frame setup
//   FramingSolver   a Solver that wraps another and renders a frame at step 0 and every
//                   render.every steps while run_simulation advances it: from the GPU
//                   solver's buffers, or (CPU solver) from read_state through HostInputs
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "compute/context.h"
#include "engine/solver.h"
#include "render/splat_renderer.h"

namespace phyxel::render {

struct FrameWriterOptions {
  RenderSettings::Mode mode = RenderSettings::Mode::Mono;  // Mono or Stereo
  std::filesystem::path out_dir;
  std::string device = "gpu";  // for a context of its own (see gpu::ContextOptions::device)
  bool validation = gpu::validation_default();
};

class FrameWriter {
 public:
  // Renders on `ctx` when given (it must outlive the writer; the GPU solver's context), else
  // on a context of its own. Throws SceneError naming the scene file and key for a bad
  // texture or a frame size the device cannot render.
  FrameWriter(const Scene& scene, const PhyxelSet& set, const FrameWriterOptions& options,
              gpu::Context* ctx = nullptr);
  ~FrameWriter();

  // Renders the state in `inputs` (a GPU solver's buffers) and writes frame_NNNNNN.png.
  // Returns the file name (relative to out_dir).
  std::string write(int64_t step, const RenderInputs& inputs);
  // The same for a state on the host: uploads u into buffers of its own (made on first use
  // from `neighbours`, the solver's rest neighbour lists).
  std::string write(int64_t step, const std::vector<Vec3>& displacement,
                    const NeighbourLists& neighbours);
  // Renders without writing (for the viewer and tests).
  RgbaImage render(const RenderInputs& inputs);

  gpu::Context& context() { return *ctx_; }
  const FrameSetup& setup() const { return setup_; }
  void set_setup(const FrameSetup& setup) { setup_ = setup; }
  const Camera& camera() const { return camera_; }
  const std::vector<std::string>& written() const { return written_; }
  static std::string frame_name(int64_t step);

 private:
  std::unique_ptr<gpu::Context> own_ctx_;
  gpu::Context* ctx_;
  const PhyxelSet* set_;
  FrameWriterOptions options_;
  Camera camera_;
  FrameSetup setup_;
  std::unique_ptr<SplatRenderer> renderer_;
  std::unique_ptr<HostInputs> host_;
  std::vector<std::string> written_;
};

class FramingSolver final : public Solver {
 public:
  // `every` steps between frames, `substeps` solver substeps per step (the run's time-step
  // plan). Writes the frame of step 0 at once. With `gpu_inputs` (a GPU solver's buffers,
  // on the writer's context) frames are rendered from them; else from read_state().
  FramingSolver(Solver& inner, FrameWriter& writer, int64_t every, int64_t substeps,
                std::function<RenderInputs()> gpu_inputs = {});

  std::string device() const override { return inner_.device(); }
  void advance(int64_t substeps, double dt) override;
  Energies energies() override { return inner_.energies(); }
  long first_non_finite() override { return inner_.first_non_finite(); }
  PointState read_state(bool with_stress) override { return inner_.read_state(with_stress); }
  size_t regularised_count() const override { return inner_.regularised_count(); }
  const NeighbourLists& neighbours() const override { return inner_.neighbours(); }
  bool supports_pass_selection() const override { return inner_.supports_pass_selection(); }
  void set_pass_selection(bool on) override { inner_.set_pass_selection(on); }
  void set_object_awake(uint32_t object, bool awake) override {
    inner_.set_object_awake(object, awake);
  }
  size_t stress_pass_size() const override { return inner_.stress_pass_size(); }
  size_t force_pass_size() const override { return inner_.force_pass_size(); }
  bool supports_load_changes() const override { return inner_.supports_load_changes(); }
  void set_external_forces(const std::vector<Vec3>& f) override { inner_.set_external_forces(f); }

  // Writes the frame of `step` unless it was written already (the run's last step).
  void finish(int64_t step);

 private:
  void write_frame(int64_t step);

  Solver& inner_;
  FrameWriter& writer_;
  std::function<RenderInputs()> gpu_inputs_;
  int64_t every_substeps_, substeps_per_step_;
  int64_t done_ = 0, next_frame_ = 0, last_written_ = -1;
};

}  // namespace phyxel::render
