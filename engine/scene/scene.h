// Scene model: what a scene file describes, in SI units, after validation.
// Parsing and validation live in scene_json.cpp; this header holds only data.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/geometry/shape.h"
#include "engine/scene/tool_desc.h"

namespace phyxel {

// Every error about user input. what() is one line: "FILE: JSON.PATH: problem; allowed ...".
struct SceneError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Material {
  double young = 0;    // E, Pa (> 0)
  double poisson = 0;  // nu, in (-1, 0.5)
  double density = 0;  // rho, kg/m^3 (> 0)
  double damping = 0;  // mass-proportional, 1/s (>= 0): force -damping*m*v
  // Volume-conservation stiffness k_v (Pa) of the energy k_v/2 (det F - 1)^2 per unit volume.
  // The St Venant-Kirchhoff lambda is lowered by k_v so small-strain E and nu are unchanged.
  // Unset: half of Lame's lambda.
  std::optional<double> volume_stiffness;
  // Dimensionless hourglass (zero-energy mode) control strength gamma (>= 0).
  double hourglass = 0.05;
  // Strength (Pa, > 0): the material tears where its largest principal Cauchy stress reaches
  // this (paper section V). Unset: it never tears.
  std::optional<double> tear_stress;
};

struct Inclusion {
  std::string name;
  Shape shape;
  Material material;
  // Appearance: the fraction (0 ... 1) of its surface colour that mirrors render.environment
  // (cube mirror environment mapping, the paper's eqs 33-34); 0: only the texture.
  double mirror = 0;
};

// An external force spread over the phyxels inside `region`, weighted by volume, acting
// during [from, until) of simulated time (always, by default).
struct Load {
  Shape region;
  Vec3 force = Vec3::Zero();                               // total force, N
  double from = 0;                                         // s
  double until = std::numeric_limits<double>::infinity();  // s
};

// Neighbours (within the support radius, not all in one plane) every phyxel needs for a usable
// MLS fit: 3 make its moment matrix invertible, the fourth leaves room to spare. So an object
// needs at least kMinMlsNeighbours + 1 phyxels; the scene reader checks the support radius
// against it and sampling checks every phyxel (docs/scene-format.md).
inline constexpr int kMinMlsNeighbours = 4;

struct ObjectDesc {
  std::string name;
  Shape shape;
  double spacing = 0;         // lattice spacing s, m
  double support_radius = 0;  // h, m (the loader fills the default 2*s)
  Material material;
  std::vector<Inclusion> inclusions;  // later ones win where they overlap
  std::vector<Shape> fixed;           // phyxels inside any of these never move
  std::vector<Load> loads;
  Vec3 initial_velocity = Vec3::Zero();
  double mirror = 0;  // as Inclusion::mirror, for the object's own phyxels
  // > 0: the SCNI band within this many spacings of a blade's cut (docs/cutting.md); 0: off.
  double cut_band = 0;
};

struct UntilRest {
  bool enabled = false;
  double kinetic_energy_below = 0;  // J
  int64_t for_steps = 1000;         // the energy must stay below the bound this long
};

// Objects at rest are put to sleep: their phyxels are skipped until a load changes.
struct SleepSettings {
  bool enabled = false;
  double kinetic_energy_below = 0;  // J, per object
  int64_t for_steps = 500;          // the object's energy must stay below the bound this long
};

struct SimulationSettings {
  double dt = 1e-4;  // requested step, s
  int64_t steps = 1000;
  Vec3 gravity = Vec3::Zero();
  UntilRest until_rest;
  SleepSettings sleep;
  // Courant factor C of the stable step dt <= C * s / c_p (see docs/decisions.md).
  double courant = 0.5;
};

struct OutputSettings {
  int64_t every = 0;    // write points_NNNNNN.vtp every this many steps (0: only the last)
  bool binary = false;  // VTK XML appended raw binary instead of ASCII
};

// `camera`: a pinhole camera (render/camera.h builds the eye frusta from it).
struct CameraSettings {
  std::optional<Vec3> position;  // unset: looking at the scene's bounding box
  std::optional<Vec3> target;    // unset: the centre of the scene's bounding box
  Vec3 up = Vec3::UnitZ();
  double fov_y_deg = 45;         // vertical field of view ("aperture")
  double near = 0.01, far = 10;  // m, 0 < near < far
};

// `render.stereo`: parallel eyes, off-axis frusta (DESIGN.md section 5).
struct StereoSettings {
  enum class Layout { SideBySide, Anaglyph };
  double ipd = 0.064;                    // eye separation, m (>= 0)
  std::optional<double> focal_distance;  // zero-parallax distance, m; unset: camera to target
  Layout layout = Layout::SideBySide;
  bool swap_eyes = false;
};

// `render.backdrop`: a rigid, never simulated surface of the surgical field (drapes, scalp,
// skull, chest wall) drawn around the objects as static splats (render/backdrop.h). The
// surface of `shape` is sampled every `spacing`, without the part inside `hole`.
struct BackdropItem {
  enum class Look { Drape, Skin, Bone, Tissue };
  std::string name;
  Shape shape;
  double spacing = 0;  // m (> 0)
  Look look = Look::Drape;
  Vec3 colour = Vec3::Zero();   // RGB in [0, 1] (as texture texels): the look's base colour
  std::optional<Shape> hole;    // unset: nothing cut out
  std::optional<Shape> within;  // unset: the whole surface; else only its part inside this
};

// `render.instruments`: rigid instruments drawn where they lie (as the tools are: polished
// steel balls or capsules) but never simulated: nothing touches them.
struct InstrumentDrawable {
  std::string name;
  ToolShape shape;
  ToolPose pose;  // the tip and the unit axis of the shaft
};

// `render`: splat rendering of the surface phyxels (render/).
struct RenderSettings {
  enum class Mode { None, Mono, Stereo };
  Mode mode = Mode::None;
  int width = 1280, height = 720;  // pixels per eye
  int64_t every = 10;              // a frame every this many steps
  std::filesystem::path texture;   // resolved against the scene's folder; empty: procedural
  StereoSettings stereo;
  // `render.environment`: the surroundings, a square image mapped on a cube (the paper's eqs
  // 33-34): the frames' background and what `mirror` surfaces reflect. Empty: none (a plain
  // dark background).
  std::filesystem::path environment;
  double environment_area_ratio = 1;  // K of eq 33: texture area / cube area of the top face
  // `render.video_texture` (the paper's section VI): a video file mapped on the objects'
  // surfaces in place of `texture`, advancing with simulated time (render/video_texture.h).
  // Empty file: none.
  struct VideoTexture {
    std::filesystem::path file;    // resolved against the scene's folder
    int loop_blend = 0;            // B: the last B frames blended into the first B (eq 32)
    bool repair_specular = false;  // specular spots found (eq 31) and repaired in every frame
  } video_texture;
  // `render.video`: an H.264 MP4 of the frames (render/video_writer.h); empty: none.
  std::filesystem::path video;
  std::vector<BackdropItem> backdrop;           // `render.backdrop`; empty: none
  std::vector<InstrumentDrawable> instruments;  // `render.instruments`; empty: none
};

struct Scene {
  std::filesystem::path file;  // where it was read from (empty if built in code)
  SimulationSettings simulation;
  std::vector<ObjectDesc> objects;
  OutputSettings output;
  CameraSettings camera;
  RenderSettings render;
  std::vector<ToolDesc> tools;  // `tools`: instruments (engine/scene/tool_desc.h)
  double refine = 1;            // K of refine_scene (1: as the file says)

  // Whether anything can tear, so that the solvers compute the largest principal stress of
  // every phyxel each step (and the outputs carry it): for now a material of an object or an
  // inclusion with tear_stress. The hook for the tearing tools (suction, grasper) to come.
  bool tearing_possible() const {
    for (const ObjectDesc& o : objects) {
      if (o.material.tear_stress) return true;
      for (const Inclusion& inc : o.inclusions)
        if (inc.material.tear_stress) return true;
    }
    return false;
  }
};

// Reads and validates a scene file. Throws SceneError naming the file and JSON path.
Scene load_scene(const std::filesystem::path& file);
// Same, from JSON text; `file` is used for messages and to resolve relative paths.
Scene parse_scene(const std::string& json_text, const std::filesystem::path& file);

// The largest --refine K the commands accept: K^3 times the phyxels.
inline constexpr double kMaxRefine = 16;

// `--refine K`: every object's spacing and support radius divided by K (a real number, 1 ...
// kMaxRefine), so the same tissue has K^3 times the phyxels; tools, paths, materials, times and
// the backdrop stay as they are. Records K in scene.refine (refinements multiply). Throws
// std::invalid_argument for a K outside that range.
void refine_scene(Scene& scene, double factor);

// Lame parameters of a material.
inline double lame_lambda(const Material& m) {
  return m.young * m.poisson / ((1 + m.poisson) * (1 - 2 * m.poisson));
}
inline double lame_mu(const Material& m) {
  return m.young / (2 * (1 + m.poisson));
}
inline double volume_stiffness(const Material& m) {
  return m.volume_stiffness ? *m.volume_stiffness : 0.5 * lame_lambda(m);
}
// P-wave speed c_p = sqrt((lambda + 2 mu) / rho).
inline double p_wave_speed(const Material& m) {
  return std::sqrt((lame_lambda(m) + 2 * lame_mu(m)) / m.density);
}

// A haptic tool's default top speed in simulated time, as a share of the slowest p-wave speed
// of the scene's tissue (docs/haptics.md, "Speed"): a probe driven into brain at 0.1 c_p moves
// no phyxel faster than itself; at 0.3 c_p the run turns unstable.
inline constexpr double kLiveSpeedPerWave = 0.1;

// The top speed of `tool` under haptic control (m/s, simulated time): its coupling's
// max_speed, else kLiveSpeedPerWave times the slowest p-wave speed of the scene's objects and
// inclusions (infinite in a scene without tissue).
inline double live_tool_speed(const Scene& scene, const ToolDesc& tool) {
  if (tool.coupling.max_speed > 0) return tool.coupling.max_speed;
  double slowest = std::numeric_limits<double>::infinity();
  for (const ObjectDesc& o : scene.objects) {
    slowest = std::min(slowest, p_wave_speed(o.material));
    for (const Inclusion& inc : o.inclusions)
      slowest = std::min(slowest, p_wave_speed(inc.material));
  }
  return kLiveSpeedPerWave * slowest;
}
inline std::vector<double> live_tool_speeds(const Scene& scene) {
  std::vector<double> speeds;
  for (const ToolDesc& t : scene.tools) speeds.push_back(live_tool_speed(scene, t));
  return speeds;
}

}  // namespace phyxel
