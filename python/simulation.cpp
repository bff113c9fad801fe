#include "python/simulation.h"

#include <utility>

#include "app/run_report.h"
#include "compute/gpu_solver.h"
#include "engine/run/run_schedule.h"
#include "engine/run/vtp_writer.h"
#include "render/frame_output.h"
#include "render/tool_raycast.h"

namespace phyxel::python {

// One frame writer per mode and size asked for last (made again when they change).
struct Simulation::Renderer {
  std::string mode;
  int width = 0, height = 0;
  Scene scene;  // the scene with that mode and size
  std::unique_ptr<render::FrameWriter> writer;
};

namespace {

std::unique_ptr<Solver> make_solver(const Scene& scene, const PhyxelSet& set,
                                    const SimulationOptions& options) {
  if (options.device == "cpu")
    return make_cpu_solver(set, scene.simulation.gravity, options.threads, false);
  gpu::ContextOptions context;
  context.device = options.device;
  return make_gpu_solver(set, scene.simulation.gravity, context);
}

}  // namespace

Simulation::Simulation(Scene scene, uint64_t scene_hash, const SimulationOptions& options,
                       const std::filesystem::path& resume)
    : scene_(std::move(scene)), options_(options) {
  if (!resume.empty()) resumed_ = std::make_unique<Checkpoint>(read_checkpoint(resume));
  set_ = sample_scene(scene_);
  solver_ = make_solver(scene_, set_, options_);
  if (resumed_)  // as phyxel run --resume: before anything else, naming the file
    check_checkpoint_matches(*resumed_, resume, scene_hash, set_, solver_->device());
  aspiration_flags_.assign(set_.size(), 0);
  if (resumed_)  // what the aspirators took before the checkpoint
    for (const uint32_t i : resumed_->aspiration.removed)
      if (i < aspiration_flags_.size()) aspiration_flags_[i] |= kRemoved;
  run_options_.steps = resumed_ ? resumed_->step : 0;
  run_options_.pass_selection = options_.pass_selection;
  run_options_.resume = resumed_.get();
  run_options_.resume_file = resume;
  run_options_.scene_hash = scene_hash;
  // Always polled, as phyxel run is: advances without tools split exactly where a stop could
  // come, so the steps are the same bit for bit.
  run_options_.stop_requested = [this] { return stop_ && stop_(); };
  // Tools with "control": "haptic" follow their path until set_tool_pose moves them.
  run_options_.tool_pose = [this](size_t tool, double t) {
    return pose_at(scene_.tools.at(tool).path, t);
  };
  run_options_.on_aspiration = [this](const AspirationEvent& e) {
    for (uint32_t i : e.removed) aspiration_flags_[i] |= kRemoved;
    for (uint32_t i : e.exposed) aspiration_flags_[i] |= kSurface;
    aspirations_.push_back(e);
    if (renderer_) renderer_->writer->apply_aspiration(e);
  };
  loop_ = std::make_unique<RunLoop>(scene_, set_, *solver_, run_options_);
}

Simulation::~Simulation() {
  renderer_.reset();  // before the solver: it may render on the solver's context
  loop_.reset();
  solver_.reset();
}

int64_t Simulation::advance(int64_t steps, const std::function<bool()>& stop) {
  if (steps < 0) throw std::invalid_argument("advance: steps must be >= 0");
  const int64_t from = loop_->steps_done();
  loop_->extend(from + steps);
  stop_ = stop;
  try {
    while (loop_->running()) loop_->step();
  } catch (...) {
    stop_ = nullptr;
    throw;
  }
  stop_ = nullptr;
  const std::string failed = app::describe_stop(scene_, loop_->result());
  if (!failed.empty()) throw SimulationError(failed);
  return loop_->steps_done() - from;
}

std::vector<uint32_t> Simulation::flags() {
  std::vector<uint32_t> out(set_.size());
  const std::vector<uint8_t> contact = solver_->read_state(false).contact;
  for (size_t i = 0; i < out.size(); ++i) {
    out[i] = set_.flags[i] | aspiration_flags_[i];
    if (i < contact.size() && contact[i]) out[i] |= kContactFlag;
  }
  return out;
}

size_t Simulation::tool_index(const std::string& name) const {
  std::string names;
  for (size_t k = 0; k < scene_.tools.size(); ++k) {
    if (scene_.tools[k].name == name) return k;
    names += (names.empty() ? "" : ", ") + scene_.tools[k].name;
  }
  throw std::out_of_range(scene_.file.string() + ": no tool named '" + name + "'; the scene has " +
                          (names.empty() ? "no tools" : names));
}

void Simulation::set_tool_pose(size_t tool, const Vec3& position, const Vec3& axis) {
  if (!position.allFinite() || !axis.allFinite() || !(axis.norm() > 0))
    throw std::invalid_argument(
        "set_tool_pose: position and axis must be finite, the axis "
        "non-zero");
  loop_->tools().command(tool, {position, axis.normalized()}, plan().substeps);
}

nlohmann::json Simulation::summary() {
  RunOptions options = run_options_;
  options.steps = loop_->total();
  return app::run_summary(scene_, set_, *solver_, options, loop_->snapshot());
}

Resection Simulation::resection() {
  return measure_resection(scene_, set_, solver_->neighbours(), alive_pairs(*solver_));
}

double Simulation::exposure(const std::string& name) {
  // The set's materials: the objects' in order, then every object's inclusions' in order.
  std::vector<std::string> names;
  for (const ObjectDesc& o : scene_.objects) names.push_back(o.name);
  std::string inclusions;
  for (const ObjectDesc& o : scene_.objects)
    for (const Inclusion& inc : o.inclusions) {
      names.push_back(inc.name);
      inclusions += (inclusions.empty() ? "" : ", ") + inc.name;
    }
  size_t m = scene_.objects.size();
  while (m < names.size() && names[m] != name) ++m;
  if (m == names.size())
    throw std::out_of_range(scene_.file.string() + ": no inclusion named '" + name +
                            "'; the scene has " + (inclusions.empty() ? "none" : inclusions));
  const NeighbourLists& nbr = solver_->neighbours();
  const std::vector<uint8_t> alive = alive_pairs(*solver_);
  size_t boundary = 0, cut = 0;
  for (size_t i = 0; i < set_.size(); ++i) {
    if (set_.material[i] != m) continue;
    for (uint32_t p = nbr.offset[i]; p < nbr.offset[i + 1]; ++p) {
      const uint32_t j = nbr.index[p];
      if (set_.material[j] == m) continue;
      ++boundary;
      const bool removed =
          ((set_.flags[i] | aspiration_flags_[i] | set_.flags[j] | aspiration_flags_[j]) &
           kRemoved) != 0;
      if (!alive[p] || removed) ++cut;
    }
  }
  return boundary > 0 ? double(cut) / double(boundary) : 0.0;
}

render::RgbaImage Simulation::render(const std::string& mode, int width, int height) {
  if (mode != "mono" && mode != "stereo")
    throw std::invalid_argument("render: mode '" + mode + "'; allowed mono or stereo");
  if (width < 1 || height < 1) throw std::invalid_argument("render: width and height >= 1");
  auto* gpu_solver = dynamic_cast<gpu::GpuSolver*>(solver_.get());
  if (!renderer_ || renderer_->mode != mode || renderer_->width != width ||
      renderer_->height != height) {
    renderer_.reset();
    auto r = std::make_unique<Renderer>();
    r->mode = mode;
    r->width = width;
    r->height = height;
    r->scene = scene_;
    r->scene.render.width = width;
    r->scene.render.height = height;
    r->scene.render.stereo.layout = StereoSettings::Layout::SideBySide;
    render::FrameWriterOptions o;
    o.mode = mode == "stereo" ? RenderSettings::Mode::Stereo : RenderSettings::Mode::Mono;
    o.device = options_.render_device;
    o.write_files = false;
    r->writer = std::make_unique<render::FrameWriter>(
        r->scene, set_, o, gpu_solver ? &gpu_solver->context() : nullptr);
    for (const AspirationEvent& e : aspirations_) r->writer->apply_aspiration(e);
    renderer_ = std::move(r);
  }
  render::FrameWriter& writer = *renderer_->writer;
  std::vector<render::ToolDrawable> tools = render::tool_drawables(scene_.tools, time());
  for (size_t k = 0; k < tools.size(); ++k) tools[k].pose = loop_->tools().poses()[k];
  writer.set_tools(tools);
  writer.advance_video(time(), true);
  writer.follow_cuts(*solver_, gpu_solver == nullptr);
  if (gpu_solver) return writer.render(gpu_solver->buffers());
  return writer.render(solver_->read_state(false).displacement, solver_->neighbours());
}

void Simulation::save_checkpoint(const std::filesystem::path& file) {
  write_checkpoint(file, loop_->checkpoint());
}

void Simulation::write_points(const std::filesystem::path& file) {
  PointState state = solver_->read_state(true);
  if (scene_.tools.empty()) state.contact.clear();
  write_points_vtp(file, set_, state, scene_.output.binary);
}

}  // namespace phyxel::python
