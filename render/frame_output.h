// Headless frames of a run: DIR/frame_NNNNNN.png (NNNNNN the step) rendered from an offscreen
// image, with the scene's camera and render settings. Never needs a display.
//
//   FrameWriter     the renderer of one scene: surfel table, texture (the scene's
//                   render.video_texture at the frame's simulated time, render.texture or the
//                   procedural tissue texture), camera, frame setup
//   write_solver_frame  one frame of a solver's current state and the tools' poses: from the
//                   GPU solver's buffers, or (CPU solver) from read_state through HostInputs;
//                   first the cuts made since the last frame (follow_cuts): cut-face surfels,
//                   and for the CPU solver the pairs' alive mask.
//                   The run loop calls it at step 0, every render.every steps and at the end
//                   (RunOptions::on_frame), with tool_drawables(scene.tools, step x dt).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "compute/context.h"
#include "engine/solver/solver.h"
#include "engine/surgery/aspiration.h"
#include "engine/surgery/cut_faces.h"
#include "render/frame_queue.h"
#include "render/splat_renderer.h"
#include "render/video_texture.h"
#include "render/video_writer.h"

namespace phyxel::render {

struct FrameWriterOptions {
  RenderSettings::Mode mode = RenderSettings::Mode::Mono;  // Mono or Stereo
  std::filesystem::path out_dir;
  std::string device = "gpu";  // for a context of its own (see gpu::ContextOptions::device)
  bool validation = gpu::validation_default();
  // false: every frame is drawn and read back as usual but no PNG is written (`phyxel run
  // --draw-only`: what drawing costs a run, without the encoder's and the disk's share).
  bool write_files = true;
  // Also an H.264 MP4 of the frames (render/video_writer.h), frame number step / video_every
  // at video_fps frames per second; empty: none. `video_source` names where the path came
  // from in errors ("--video", "scene.json: render.video").
  std::filesystem::path video{};
  double video_fps = 30;
  int64_t video_every = 1;
  std::string video_source = "video";
};

// Host seconds of a writer's calls by part (`phyxel bench --surgery`): waiting for the frame
// in flight, the cuts' and aspirations' surfels, the video texture, recording and submitting.
struct FrameWriterTimes {
  double wait = 0, cuts = 0, aspiration = 0, video = 0, submit = 0;
  int64_t frames = 0, aspirations = 0;
};

class FrameWriter {
 public:
  // Renders on `ctx` when given (it must outlive the writer; the GPU solver's context), else
  // on a context of its own. Throws SceneError naming the scene file and key for a bad
  // texture or a frame size the device cannot render.
  FrameWriter(const Scene& scene, const PhyxelSet& set, const FrameWriterOptions& options,
              gpu::Context* ctx = nullptr);
  ~FrameWriter();

  // Renders the state in `inputs` (a GPU solver's buffers) and hands it to the writer thread
  // (frame_NNNNNN.png, the video). Returns the file name (relative to out_dir). Rethrows a
  // failure to write an earlier frame. Submits without waiting (render/frame_queue.h): the
  // frame is completed, and its pixels copied out on the writer thread, at the next call of
  // any method here that changes what the renderer reads, or at flush() and finish().
  std::string write(int64_t step, const RenderInputs& inputs);
  // The same for a state on the host: uploads u into buffers of its own (made on first use
  // from `neighbours`, the solver's rest neighbour lists).
  std::string write(int64_t step, const std::vector<Vec3>& displacement,
                    const NeighbourLists& neighbours);
  // Renders without writing (for the viewer and tests).
  RgbaImage render(const RenderInputs& inputs);
  // The same for a state on the host (the Python module's frames), as write() uploads it.
  RgbaImage render(const std::vector<Vec3>& displacement, const NeighbourLists& neighbours);
  // The scene's video texture (render.video_texture) at simulated time t from the next frame
  // on: the frame of t exactly (`exact`, waiting for the decoding thread; write() does this
  // with step x simulation.dt), or the newest one ready (the viewer). Returns whether the
  // texture changed; false without a video texture.
  bool advance_video(double t, bool exact);
  const VideoTexture* video_texture() const { return video_.get(); }
  // The tools of the frames from now on (SplatRenderer::set_tools; none at first), drawn
  // with the scene's `render.instruments` (always).
  void set_tools(std::vector<ToolDrawable> tools);
  // Cuts: reads the pairs `solver` severed since the last call (its severed_since log, from
  // this writer's cursor), adds them to the cut faces and updates the renderer's cut-face
  // surfels of the phyxels they touched. With `host_state` (a CPU solver, frames through
  // write(step, displacement, ...)), also uploads solver.pair_alive() to the host inputs when
  // the severed count changed, so the deform pass skips severed pairs; a GPU solver's buffers
  // carry its pair weights themselves. Returns whether anything was severed since last time.
  bool follow_cuts(Solver& solver, bool host_state);
  const CutFaces& cut_faces() const { return cuts_; }
  SplatRenderer& renderer();  // completes the frame in flight first
  // An aspiration (engine/surgery/aspiration.h): the removed phyxels' surfels hidden, the
  // exposed ones drawn as torn fracture surface facing the mouth (rough, with the eq 27
  // falloff around the tool's axis; docs/suction.md).
  void apply_aspiration(const AspirationEvent& event);

  gpu::Context& context() { return *ctx_; }
  const FrameSetup& setup() const { return setup_; }
  void set_setup(const FrameSetup& setup);  // completes and copies out the frames in flight
  const Camera& camera() const { return camera_; }
  const std::vector<std::string>& written() const { return written_; }
  static std::string frame_name(int64_t step);
  const FrameWriterTimes& times() const { return times_; }
  // Waits until the writer thread has written every frame so far (the files exist);
  // rethrows a failure.
  void flush();
  // flush(), and finishes the video. Call before the writer is destroyed to hear of
  // failures (the destructor waits too but ignores them).
  void finish();

 private:
  std::unique_ptr<gpu::Context> own_ctx_;
  gpu::Context* ctx_;
  const PhyxelSet* set_;
  FrameWriterOptions options_;
  Camera camera_;
  FrameSetup setup_;
  std::unique_ptr<VideoTexture> video_;    // render.video_texture, decoded on its own thread
  double dt_ = 0;                          // simulation.dt: a frame's step to simulated time
  std::vector<ToolDrawable> instruments_;  // render.instruments: drawn, never simulated
  std::unique_ptr<SplatRenderer> renderer_;
  std::unique_ptr<HostInputs> host_;
  std::unique_ptr<FrameSink> sink_;    // PNG files and the video, on a thread of its own
  std::unique_ptr<FrameQueue> queue_;  // frames submitted without waiting (after sink_)
  std::vector<std::string> written_;
  CutFaces cuts_;
  size_t cut_cursor_ = 0;  // entries of the solver's severed log already in cuts_
  size_t alive_at_ = 0;    // severed count of the last pair_alive upload to host_
  FrameWriterTimes times_;
  void drain();  // queue_->drain(), timed
};

// Renders the frame of `step` from `solver` with the tools at `tools` (their poses at the
// step's simulated time; empty: none): from `gpu_inputs` (a GPU solver's buffers on the
// writer's context) when given, else from the solver's displacement. Returns the file name.
std::string write_solver_frame(FrameWriter& writer, Solver& solver, int64_t step,
                               const std::vector<ToolDrawable>& tools,
                               const std::function<RenderInputs()>& gpu_inputs = {});

}  // namespace phyxel::render
