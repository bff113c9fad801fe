// Scene files: JSON text -> Scene, with strict validation. The format is documented in
// docs/scene-format.md; every error names the file, the JSON path and what is allowed.
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "engine/geometry/mesh.h"
#include "engine/geometry/shape.h"
#include "engine/scene/file_kind.h"
#include "engine/scene/json_reader.h"
#include "engine/scene/scene.h"
#include "engine/scene/scene_json_tools.h"
#include "engine/scene/scene_limits.h"

namespace phyxel {
namespace {

namespace fs = std::filesystem;
using json_reader::Limits;
using json_reader::Node;

constexpr std::string_view kMaterialExpected =
    "a material object {\"young\": Pa, \"poisson\": 1, \"density\": kg/m^3, ...}";
// A phyxel at a convex lattice corner needs this many neighbours for a usable MLS fit.
constexpr int kMinCornerNeighbours = kMinMlsNeighbours;
// Memory per phyxel (state, neighbour lists, solver buffers), bytes: measured as the peak
// resident size of `phyxel run` (CPU, double) on boxes of 69k and 227k phyxels at support
// radius 2 and 3 x spacing: 1 590 B at 26 neighbours, 2 340 B at 92 (docs/decisions.md).
constexpr double kBytesPerPhyxelBase = 1300;
constexpr double kBytesPerNeighbour = 12;
double bytes_per_phyxel(const ObjectDesc& o) {
  const double ratio = o.support_radius / o.spacing;
  return kBytesPerPhyxelBase + kBytesPerNeighbour * (4.18879 * ratio * ratio * ratio - 1);
}
// Materials from foam to steel (tissue: 1e2-1e7 Pa, cortical bone 2e10 Pa); values outside make
// the stable step vanish or the p-wave speed overflow long before a run could use them.
const Limits kYoungLimits = Limits::above_up_to(0, 1e12);
const Limits kDensityLimits{1, 1e5, true, true};
// Neighbours within support_radius grow with (support_radius / spacing)^3: 5 x spacing is
// about 520 per phyxel, far past the 2 x (about 30) the model needs.
constexpr double kMaxSupportFactor = 5;
// Scene files are a few kilobytes; a larger one is not a scene (and would be read whole).
constexpr uintmax_t kMaxSceneFileBytes = uintmax_t(64) << 20;

void check_box(const Node& node, const Shape& s) {
  for (int axis = 0; axis < 3; ++axis) {
    if (!(s.max[axis] > s.min[axis])) {
      const std::string i = "[" + std::to_string(axis) + "]";
      node.find("max")->fail("max" + i + " = " + json_reader::format_number(s.max[axis]) +
                                 " is not greater than min" + i + " = " +
                                 json_reader::format_number(s.min[axis]),
                             "allowed min < max on every axis (x, y, z)");
    }
  }
}

void read_mesh_file(const Node& path_node, Shape& s, const fs::path& folder) {
  // Built by appending: GCC 12 warns falsely (-Wrestrict) about "literal" + std::string&&.
  std::string allowed =
      "allowed a path to a closed triangle surface in OBJ, STL or PLY format, relative to the "
      "scene file's folder (";
  allowed += folder.empty() ? std::string("the working directory") : folder.string();
  allowed += ")";
  if (const std::string why = not_a_regular_file(s.path); !why.empty())
    path_node.fail("mesh file \"" + s.path.string() + "\" " + why, allowed);
  try {
    s.mesh = std::make_shared<const TriangleMesh>(load_mesh(s.path, s.scale));
  } catch (const std::exception& e) {
    path_node.fail("cannot use mesh file \"" + s.path.string() + "\": " + e.what(), allowed);
  }
}

}  // namespace

// Declared in scene_json_tools.h (the backdrop's shapes use it too).
Shape read_shape(const Node& node, const fs::path& folder, ImageReads* images) {
  node.expect_object(kShapeExpected, {"type", "min", "max", "center", "radius", "radii", "path",
                                      "scale", "file", "labels", "threshold", "frame"});
  const std::string type =
      node.at("type", "\"box\", \"sphere\", \"ellipsoid\", \"mesh\" or \"image\"")
          .choice({"box", "sphere", "ellipsoid", "mesh", "image"});
  if (type == "image") return read_image_shape(node, folder, images);
  Shape s;
  if (type == "box") {
    node.expect_object("a box", {"type", "min", "max"});
    s.type = Shape::Type::Box;
    s.min = node.vec3("min", Limits::any(), "m");
    s.max = node.vec3("max", Limits::any(), "m");
    check_box(node, s);
  } else if (type == "sphere") {
    node.expect_object("a sphere", {"type", "center", "radius"});
    s.type = Shape::Type::Sphere;
    s.center = node.vec3("center", Limits::any(), "m");
    s.radius = node.number("radius", Limits::above(0), "m");
  } else if (type == "ellipsoid") {
    node.expect_object("an ellipsoid", {"type", "center", "radii"});
    s.type = Shape::Type::Ellipsoid;
    s.center = node.vec3("center", Limits::any(), "m");
    s.radii = node.vec3("radii", Limits::above(0), "m");
  } else {
    node.expect_object("a mesh", {"type", "path", "scale"});
    s.type = Shape::Type::Mesh;
    const Node path_node =
        node.at("path", "the OBJ, STL or PLY file, relative to the scene file's folder");
    s.path = folder / path_node.text();
    s.scale = node.number_or("scale", 1.0, Limits::above(0), "");
    read_mesh_file(path_node, s, folder);
  }
  return s;
}

namespace {

// Inclusions start from the host's material: damping, hourglass, volume_stiffness and
// tear_stress default to the host's values; young, poisson and density are always required.
Material read_material(const Node& node, const Material& defaults) {
  node.expect_object(kMaterialExpected, {"young", "poisson", "density", "damping",
                                         "volume_stiffness", "hourglass", "tear_stress"});
  Material m = defaults;
  m.young = node.number("young", kYoungLimits, "Pa");
  m.poisson = node.number("poisson", Limits::open(-1, 0.5), "");
  m.density = node.number("density", kDensityLimits, "kg/m^3");
  m.damping = node.number_or("damping", m.damping, Limits::at_least(0), "1/s");
  m.hourglass = node.number_or("hourglass", m.hourglass, Limits::at_least(0), "");
  if (const auto kv = node.find("volume_stiffness")) {
    m.volume_stiffness = kv->number(Limits::at_least(0), "Pa");
  }
  if (const auto tear = node.find("tear_stress")) {
    m.tear_stress = tear->number(Limits::above(0), "Pa");
  }
  return m;
}

// Fails unless a phyxel at a convex lattice corner (offsets k >= 0 componentwise) has at least
// kMinCornerNeighbours neighbours with |k| * spacing < support_radius.
void check_support_radius(const Node& node, const ObjectDesc& o) {
  std::vector<double> corner, interior;  // |k| of lattice offsets, in units of the spacing
  for (int i = -2; i <= 2; ++i) {
    for (int j = -2; j <= 2; ++j) {
      for (int k = -2; k <= 2; ++k) {
        if (i == 0 && j == 0 && k == 0) continue;
        const double norm = std::sqrt(double(i * i + j * j + k * k));
        interior.push_back(norm);
        if (i >= 0 && j >= 0 && k >= 0) corner.push_back(norm);
      }
    }
  }
  std::sort(corner.begin(), corner.end());
  const auto within = [&](const std::vector<double>& norms) {
    return std::count_if(norms.begin(), norms.end(),
                         [&](double n) { return n * o.spacing < o.support_radius; });
  };
  const auto corner_count = within(corner);
  if (corner_count >= kMinCornerNeighbours) return;
  const double factor = corner[kMinCornerNeighbours - 1];  // sqrt(2)
  const Node h = *node.find("support_radius");
  h.fail(json_reader::format_number(o.support_radius) + " gives a phyxel at a lattice corner " +
             std::to_string(corner_count) + " neighbours and an interior phyxel " +
             std::to_string(within(interior)) + ", too few for a stable MLS fit",
         "allowed support_radius > " + json_reader::format_approx(factor * o.spacing) +
             " (sqrt(2) * spacing, at least " + std::to_string(kMinCornerNeighbours) +
             " neighbours at a corner); the default 2 * spacing = " +
             json_reader::format_approx(2 * o.spacing) + " is recommended");
}

template <typename T, typename Read>
std::vector<T> read_list(const Node& object, std::string_view key, std::string_view expected,
                         Read read) {
  std::vector<T> out;
  if (const auto list = object.find(key)) {
    for (const Node& element : list->elements(expected)) out.push_back(read(element));
  }
  return out;
}

// `mirror`: the fraction of a surface's colour that reflects render.environment.
const Limits kMirrorLimits{0, 1, true, true};
// `cut_band`: spacings round a blade's cut integrated by the SCNI band (0: off).
const Limits kCutBandLimits{0, 6, true, true};

ObjectDesc read_object(const Node& node, const fs::path& folder, ImageReads* images) {
  node.expect_object("an object description",
                     {"name", "shape", "spacing", "support_radius", "material", "inclusions",
                      "fixed", "loads", "initial_velocity", "mirror", "cut_band"});
  ObjectDesc o;
  o.name = node.at("name", "a non-empty string").text();
  o.shape = read_shape(node.at("shape", kShapeExpected), folder, images);
  o.spacing = node.number("spacing", Limits::above(0), "m");
  o.support_radius = node.number_or("support_radius", 2 * o.spacing,
                                    Limits::above_up_to(0, kMaxSupportFactor * o.spacing), "m");
  check_support_radius(node, o);
  o.material = read_material(node.at("material", kMaterialExpected), Material{});
  o.mirror = node.number_or("mirror", 0.0, kMirrorLimits, "");
  o.cut_band = node.number_or("cut_band", 0.0, kCutBandLimits, "spacings");

  std::map<std::string, std::string> inclusion_paths;  // name -> path, for duplicates
  o.inclusions =
      read_list<Inclusion>(node, "inclusions", "an array of inclusion objects", [&](const Node& n) {
        n.expect_object("an inclusion object", {"name", "shape", "material", "mirror"});
        Inclusion inc;
        const auto name = n.find("name");
        inc.name = name ? name->text() : "inclusion" + std::to_string(inclusion_paths.size());
        const std::string at = name ? name->path() : n.path();
        if (const auto [it, fresh] = inclusion_paths.emplace(inc.name, at); !fresh) {
          json_reader::fail(
              n.file(), at,
              "duplicate inclusion name \"" + inc.name + "\" (also " + it->second + ")",
              "allowed a name that no other inclusion of this object uses");
        }
        inc.shape = read_shape(n.at("shape", kShapeExpected), folder, images);
        inc.material = read_material(n.at("material", kMaterialExpected), o.material);
        inc.mirror = n.number_or("mirror", 0.0, kMirrorLimits, "");
        return inc;
      });
  o.fixed = read_list<Shape>(node, "fixed", "an array of shape objects",
                             [&](const Node& n) { return read_shape(n, folder, images); });
  o.loads = read_list<Load>(node, "loads", "an array of load objects", [&](const Node& n) {
    n.expect_object("a load object {\"region\": shape, \"force\": [x, y, z]}",
                    {"region", "force", "from", "until"});
    Load load;
    load.region = read_shape(n.at("region", kShapeExpected), folder, images);
    load.force = n.vec3("force", Limits::any(), "N");
    load.from = n.number_or("from", 0.0, Limits::at_least(0), "s");
    if (n.find("until")) {
      load.until = n.number_or("until", 0.0, Limits::above(load.from), "s");
    }
    return load;
  });
  o.initial_velocity = node.vec3_or("initial_velocity", Vec3::Zero(), Limits::any(), "m/s");
  return o;
}

SimulationSettings read_simulation(const Node& node) {
  node.expect_object("a simulation object {\"dt\": s, \"steps\": n, ...}",
                     {"dt", "steps", "gravity", "until_rest", "sleep", "courant"});
  SimulationSettings s;
  s.dt = node.number("dt", Limits::above(0), "s");
  s.steps = node.integer("steps", Limits::at_least(0));
  s.gravity = node.vec3_or("gravity", Vec3::Zero(), Limits::any(), "m/s^2");
  if (const auto rest = node.find("until_rest")) {
    rest->expect_object("an until_rest object {\"kinetic_energy_below\": J, \"for_steps\": n}",
                        {"kinetic_energy_below", "for_steps"});
    s.until_rest.enabled = true;
    s.until_rest.kinetic_energy_below = rest->number("kinetic_energy_below", Limits::above(0), "J");
    s.until_rest.for_steps = rest->integer_or("for_steps", 1000, Limits::at_least(1));
  }
  if (const auto sleep = node.find("sleep")) {
    sleep->expect_object("a sleep object {\"kinetic_energy_below\": J, \"for_steps\": n}",
                         {"kinetic_energy_below", "for_steps"});
    s.sleep.enabled = true;
    s.sleep.kinetic_energy_below = sleep->number("kinetic_energy_below", Limits::above(0), "J");
    s.sleep.for_steps = sleep->integer_or("for_steps", 500, Limits::at_least(1));
  }
  s.courant = node.number_or("courant", 0.5, Limits::above_up_to(0, 1), "");
  return s;
}

OutputSettings read_output(const Node& node) {
  node.expect_object("an output object {\"every\": n, \"format\": \"ascii\" | \"binary\"}",
                     {"every", "format"});
  OutputSettings out;
  out.every = node.integer_or("every", 0, Limits::at_least(0));
  if (const auto format = node.find("format"))
    out.binary = format->choice({"ascii", "binary"}) == "binary";
  return out;
}

double bounds_volume(const Shape& s) {
  const Eigen::AlignedBox3d box = shape_bounds(s);
  return box.isEmpty() ? 0.0 : box.volume();
}

// Estimates the phyxel count (bounding-box volume / spacing^3) of every object and fails,
// blaming the largest object's spacing, when the scene would not fit in physical memory.
void check_memory(const std::string& file, const std::vector<ObjectDesc>& objects) {
  const double memory = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGESIZE));
  std::vector<double> phyxels, bytes;
  for (const ObjectDesc& o : objects) {
    phyxels.push_back(bounds_volume(o.shape) / (o.spacing * o.spacing * o.spacing));
    bytes.push_back(phyxels.back() * bytes_per_phyxel(o));
  }
  double total = 0, total_bytes = 0;
  for (size_t k = 0; k < phyxels.size(); ++k) {
    total += phyxels[k];
    total_bytes += bytes[k];
  }
  if (!(total_bytes > memory)) return;
  const size_t i = std::max_element(bytes.begin(), bytes.end()) - bytes.begin();
  const double each = bytes_per_phyxel(objects[i]);
  const double others = total_bytes - bytes[i];
  std::string allowed = "a larger spacing is needed";
  if (others < memory) {
    const double needed = std::cbrt(bounds_volume(objects[i].shape) * each / (memory - others));
    allowed += ": spacing > " + json_reader::format_approx(needed) + " for this object";
  } else {
    allowed += " here and in the other objects";
  }
  using json_reader::format_approx;
  json_reader::fail(
      file, "objects[" + std::to_string(i) + "].spacing",
      json_reader::format_number(objects[i].spacing) + " gives about " + format_approx(phyxels[i]) +
          " phyxels (the scene about " + format_approx(total) + " phyxels, " +
          format_approx(total_bytes) + " bytes at about " + format_approx(std::round(each)) +
          " bytes each), more than this machine's memory of " + format_approx(memory) + " bytes",
      allowed);
}

}  // namespace

// `camera` and `render` (scene_json_render.cpp).
void read_view_settings(const Node& root, Scene& scene);

Scene parse_scene(const std::string& json_text, const fs::path& file) {
  const std::string name = file.string();
  const nlohmann::json doc = json_reader::parse_document(json_text, name);
  const Node root(doc, "", name);
  root.expect_object(
      "a scene object {\"simulation\": {...}, \"objects\": [...], \"output\": {...}}",
      {"simulation", "objects", "output", "camera", "render", "tools"});
  Scene scene;
  scene.file = file;
  scene.simulation =
      read_simulation(root.at("simulation", "a simulation object with dt and steps"));

  const Node objects = root.at("objects", "an array of one or more objects");
  const std::vector<Node> list = objects.elements("an array of one or more objects");
  if (list.empty()) objects.fail("empty array", "allowed an array of one or more objects");
  std::map<std::string, std::string> names;  // name -> path of its first use
  ImageReads images;                         // each image file read once
  for (const Node& node : list) {
    scene.objects.push_back(read_object(node, file.parent_path(), &images));
    const std::string path = node.path() + ".name";
    if (const auto [it, fresh] = names.emplace(scene.objects.back().name, path); !fresh) {
      json_reader::fail(name, path,
                        "duplicate object name \"" + it->first + "\" (also " + it->second + ")",
                        "allowed a name that no other object uses");
    }
  }
  check_memory(name, scene.objects);
  check_time_step(root, scene);

  if (const auto output = root.find("output")) scene.output = read_output(*output);
  read_view_settings(root, scene);
  read_tools(root, scene);
  check_tool_sizes(root, scene);
  return scene;
}

Scene load_scene(const fs::path& file) {
  const std::string name = file.string();
  std::error_code ec;
  if (!fs::exists(file, ec)) {
    throw SceneError(name +
                     ": cannot open the scene file (no such file); check the path (a "
                     "relative path is resolved against the working directory " +
                     fs::current_path(ec).string() + ")");
  }
  if (fs::is_directory(file, ec)) {
    throw SceneError(name + ": is a directory, not a scene file; check the path");
  }
  if (const std::string why = not_a_regular_file(file); !why.empty())
    throw SceneError(name + ": " + why + "; a scene is a JSON text file, check the path");
  if (fs::file_size(file, ec) > kMaxSceneFileBytes)
    throw SceneError(name + ": " + json_reader::format_approx(double(fs::file_size(file, ec))) +
                     " bytes, more than a scene file holds (at most " +
                     json_reader::format_approx(double(kMaxSceneFileBytes)) +
                     " bytes); check the path");
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    throw SceneError(name + ": cannot open the scene file (" + std::strerror(errno) +
                     "); check the path and the file's permissions");
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) {
    throw SceneError(name + ": cannot read the scene file (" + std::strerror(errno) +
                     "); check the path and the file's permissions");
  }
  return parse_scene(text.str(), file);
}

}  // namespace phyxel
