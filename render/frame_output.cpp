#include "render/frame_output.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>
#include <utility>

#include "render/backdrop.h"
#include "render/cut_surfels.h"
#include "render/environment_map.h"

namespace phyxel::render {
namespace {

std::string scene_name(const Scene& scene) {
  return scene.file.empty() ? std::string("<scene>") : scene.file.string();
}

// Adds the seconds from construction to destruction to `into`.
class Lap {
 public:
  explicit Lap(double& into) : into_(into), start_(std::chrono::steady_clock::now()) {}
  ~Lap() {
    into_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  Lap(const Lap&) = delete;
  Lap& operator=(const Lap&) = delete;

 private:
  double& into_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace

std::string FrameWriter::frame_name(int64_t step) {
  char name[64];
  std::snprintf(name, sizeof name, "frame_%06lld.png", static_cast<long long>(step));
  return name;
}

FrameWriter::FrameWriter(const Scene& scene, const PhyxelSet& set,
                         const FrameWriterOptions& options, gpu::Context* ctx)
    : ctx_(ctx), set_(&set), options_(options), dt_(scene.simulation.dt) {
  const std::string file = scene_name(scene);
  const RenderSettings& r = scene.render;
  RgbaImage texture;
  if (!r.video_texture.file.empty()) {
    VideoTextureOptions video;
    video.loop_blend = r.video_texture.loop_blend;
    video.repair_specular = r.video_texture.repair_specular;
    try {
      video_ = std::make_unique<VideoTexture>(r.video_texture.file, video);
    } catch (const std::runtime_error& e) {
      throw SceneError(file + ": render.video_texture: " + e.what() +
                       "; allowed a video file that FFmpeg decodes (MP4, MKV, WebM, AVI, ...)");
    }
    texture = (*video_->frame_at(0))[0];
  } else if (!r.texture.empty()) {
    texture = load_image(r.texture, file + ": render.texture");
  } else {
    texture = procedural_tissue_texture();
  }
  if (ctx_ == nullptr) {
    gpu::ContextOptions o;
    o.device = options.device;
    o.validation = options.validation;
    own_ctx_ = std::make_unique<gpu::Context>(o);
    ctx_ = own_ctx_.get();
  }
  const SurfelTable table = build_surfel_table(set, material_mirrors(scene));
  renderer_ = std::make_unique<SplatRenderer>(*ctx_, table, texture);
  camera_ = resolve_camera(scene.camera, table.bounds, double(r.width) / double(r.height), file);
  if (!r.environment.empty()) {
    renderer_->set_environment(load_environment(r.environment, file + ": render.environment"),
                               environment_basis(camera_), r.environment_area_ratio);
  }
  if (!r.backdrop.empty()) renderer_->set_backdrop(bake_backdrop(r.backdrop, camera_.position));
  for (const InstrumentDrawable& i : r.instruments) instruments_.push_back({i.shape, i.pose});
  if (!instruments_.empty()) renderer_->set_tools(instruments_);
  setup_ = make_frame_setup(camera_, r, options.mode);
  const uint32_t limit = renderer_->max_frame_side();
  const uint32_t wide = setup_.eye_count() * setup_.eye_width;
  if (wide > limit || setup_.height > limit) {
    const bool tall = setup_.height > limit;
    throw SceneError(file + ": render." + (tall ? "height" : "width") + ": a frame of " +
                     std::to_string(wide) + " x " + std::to_string(setup_.height) + " pixels" +
                     (setup_.eye_count() == 2 ? " (two eyes side by side)" : "") +
                     " is larger than " + ctx_->info().name + " renders; allowed at most " +
                     std::to_string(limit) + " pixels per side" +
                     (setup_.eye_count() == 2 ? " for both eyes together" : ""));
  }
  if (const std::string why = renderer_->frame_error(setup_); !why.empty()) {
    throw SceneError(file + ": render.width and render.height: " + why);
  }
  std::unique_ptr<VideoWriter> video;
  if (!options.video.empty()) {
    try {
      video = std::make_unique<VideoWriter>(options.video, setup_.frame_width(), setup_.height,
                                            options.video_fps);
    } catch (const std::runtime_error& e) {
      throw SceneError(options.video_source + ": " + e.what() +
                       "; allowed a file in an existing, writable folder");
    }
  }
  // Always a sink: with --draw-only its thread still copies each frame out (and drops it), so
  // that drawing costs the run what it costs with files.
  sink_ = std::make_unique<FrameSink>(options.out_dir, options.write_files, std::move(video));
  queue_ = std::make_unique<FrameQueue>(*ctx_, *renderer_, *sink_);
}

FrameWriter::~FrameWriter() {
  // The frame in flight, then the sink's copies out of the renderer, before the renderer goes.
  queue_.reset();
  sink_.reset();
}

void FrameWriter::drain() {
  const Lap lap(times_.wait);
  queue_->drain();
}

void FrameWriter::flush() {
  drain();
  sink_->flush();
}

void FrameWriter::finish() {
  drain();
  sink_->finish();
}

void FrameWriter::set_setup(const FrameSetup& setup) {
  drain();
  sink_->flush();  // the read-back slots are made again for another size
  setup_ = setup;
}

SplatRenderer& FrameWriter::renderer() {
  drain();
  return *renderer_;
}

RgbaImage FrameWriter::render(const RenderInputs& inputs) {
  drain();
  return renderer_->render(inputs, setup_);
}

RgbaImage FrameWriter::render(const std::vector<Vec3>& displacement,
                              const NeighbourLists& neighbours) {
  drain();
  if (!host_) host_ = std::make_unique<HostInputs>(*ctx_, *set_, neighbours);
  host_->set_displacement(displacement);
  return render(host_->inputs());
}

void FrameWriter::set_tools(std::vector<ToolDrawable> tools) {
  drain();
  tools.insert(tools.end(), instruments_.begin(), instruments_.end());
  renderer_->set_tools(std::move(tools));
}

bool FrameWriter::advance_video(double t, bool exact) {
  if (!video_) return false;
  drain();
  const Lap lap(times_.video);
  const std::vector<RgbaImage>* levels = exact ? video_->frame_at(t) : video_->newest(t);
  if (levels == nullptr) return false;
  renderer_->set_texture(*levels);
  return true;
}

std::string FrameWriter::write(int64_t step, const RenderInputs& inputs) {
  advance_video(double(step) * dt_, true);
  const std::string name = frame_name(step);
  const int64_t every = std::max<int64_t>(options_.video_every, 1);
  drain();
  const Lap lap(times_.submit);
  ++times_.frames;
  queue_->submit(inputs, setup_, name, (step + every / 2) / every);
  if (options_.write_files) written_.push_back(name);
  return name;
}

std::string FrameWriter::write(int64_t step, const std::vector<Vec3>& displacement,
                               const NeighbourLists& neighbours) {
  drain();  // the frame in flight reads the host inputs' displacement
  if (!host_) host_ = std::make_unique<HostInputs>(*ctx_, *set_, neighbours);
  host_->set_displacement(displacement);
  return write(step, host_->inputs());
}

void FrameWriter::apply_aspiration(const AspirationEvent& event) {
  drain();
  const Lap lap(times_.aspiration);
  ++times_.aspirations;
  renderer_->hide_phyxels(event.removed);
  const FractureRegion region{event.centre, event.rest_radius, event.axis};  // rest space
  std::vector<layout::SurfelStatic> faces;
  for (size_t k = 0; k < event.exposed.size(); ++k) {
    CutFace face;
    face.normal = event.exposed_normal[k];
    face.torn = true;
    faces.push_back(cut_face_surfel(*set_, event.exposed[k], face, region));
  }
  renderer_->update_cut_surfels(faces);
  alive_at_ = std::numeric_limits<size_t>::max();  // the host's pair mask changed: upload again
}

bool FrameWriter::follow_cuts(Solver& solver, bool host_state) {
  drain();
  const Lap lap(times_.cuts);
  const size_t severed = severed_pair_count(solver);
  const bool changed = severed != cut_cursor_;
  if (changed) {
    const std::vector<SeveredPair> pairs = solver.cutting()->severed_since(cut_cursor_);
    cut_cursor_ += pairs.size();
    cuts_.add(*set_, pairs);
    renderer_->update_cut_surfels(cut_face_surfels(*set_, cuts_, cuts_.take_changed()));
  }
  if (host_state && severed != alive_at_) {
    if (!host_) host_ = std::make_unique<HostInputs>(*ctx_, *set_, solver.neighbours());
    host_->set_pair_alive(alive_pairs(solver));
    alive_at_ = severed;
  }
  return changed;
}

std::string write_solver_frame(FrameWriter& writer, Solver& solver, int64_t step,
                               const std::vector<ToolDrawable>& tools,
                               const std::function<RenderInputs()>& gpu_inputs) {
  writer.set_tools(tools);
  writer.follow_cuts(solver, !gpu_inputs);
  if (gpu_inputs) return writer.write(step, gpu_inputs());
  return writer.write(step, solver.read_state(false).displacement, solver.neighbours());
}

}  // namespace phyxel::render
