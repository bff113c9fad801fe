// Scene files: `render.backdrop` (the rigid surroundings of the surgical field, drawn as static
// splats) and `render.instruments` (rigid instruments drawn as the tools are, never simulated).
// docs/scene-format.md, "Rendering". Called by read_render (scene_json_render.cpp).
#include <map>
#include <string>

#include "engine/geometry/shape.h"
#include "engine/scene/json_reader.h"
#include "engine/scene/scene.h"
#include "engine/scene/scene_json_tools.h"

namespace phyxel {
namespace {

namespace fs = std::filesystem;
using json_reader::Limits;
using json_reader::Node;

constexpr std::string_view kBackdropExpected =
    "an array of backdrop objects {\"name\": \"drape\", \"shape\": {...}, \"spacing\": m, "
    "\"look\": \"drape\" | \"skin\" | \"bone\" | \"tissue\", \"colour\": [r, g, b], \"hole\": "
    "{...}, \"within\": {...}}";
constexpr std::string_view kItemExpected =
    "a backdrop object {\"name\": \"drape\", \"shape\": {...}, \"spacing\": m, \"look\": "
    "\"drape\", \"colour\": [r, g, b], \"hole\": {...}, \"within\": {...}}";
constexpr std::string_view kInstrumentsExpected =
    "an array of instrument objects {\"name\": \"retractor\", \"shape\": {\"type\": \"capsule\", "
    "\"radius\": m, \"length\": m}, \"position\": [x, y, z], \"axis\": [x, y, z]}";

// Splats a backdrop may have (its shape's bounding-box area / spacing^2 bounds the count):
// beyond this, load time and the frames' cost grow for nothing a frame can show.
constexpr double kMaxBackdropSplats = 2e6;

// The base colour of each look (linear RGB), when the item gives none.
Vec3 default_colour(BackdropItem::Look look) {
  switch (look) {
    case BackdropItem::Look::Drape:
      return {0.30, 0.56, 0.60};  // blue-green surgical cloth
    case BackdropItem::Look::Skin:
      return {0.86, 0.64, 0.52};
    case BackdropItem::Look::Bone:
      return {0.88, 0.83, 0.70};
    case BackdropItem::Look::Tissue:
      return {0.55, 0.14, 0.12};
  }
  return Vec3::Zero();
}

BackdropItem read_item(const Node& node, const fs::path& folder) {
  node.expect_object(kItemExpected,
                     {"name", "shape", "spacing", "look", "colour", "hole", "within"});
  BackdropItem b;
  b.name = node.at("name", "a non-empty string").text();
  b.shape = read_shape(node.at("shape", kShapeExpected), folder);
  if (b.shape.type == Shape::Type::Image)
    node.at("shape", "")
        .fail("an image shape has no surface to draw as a backdrop",
              "allowed a box, sphere, ellipsoid or mesh");
  b.spacing = node.number("spacing", Limits::above(0), "m");
  const std::string look = node.at("look", "\"drape\", \"skin\", \"bone\" or \"tissue\"")
                               .choice({"drape", "skin", "bone", "tissue"});
  b.look = look == "skin"     ? BackdropItem::Look::Skin
           : look == "bone"   ? BackdropItem::Look::Bone
           : look == "tissue" ? BackdropItem::Look::Tissue
                              : BackdropItem::Look::Drape;
  b.colour = node.vec3_or("colour", default_colour(b.look), {0, 1, true, true}, "");
  if (const auto hole = node.find("hole")) b.hole = read_shape(*hole, folder);
  if (const auto within = node.find("within")) b.within = read_shape(*within, folder);
  const Eigen::Vector3d size = shape_bounds(b.shape).sizes();
  const double area = 2 * (size.x() * size.y() + size.y() * size.z() + size.z() * size.x());
  const double splats = area / (b.spacing * b.spacing);
  if (splats > kMaxBackdropSplats) {
    node.at("spacing", "")
        .fail("spacing " + json_reader::format_number(b.spacing) + " m gives up to " +
                  json_reader::format_approx(splats) + " splats on this shape",
              "allowed a spacing that gives at most " +
                  json_reader::format_approx(kMaxBackdropSplats) +
                  " (shape bounding-box area / spacing^2)");
  }
  return b;
}

}  // namespace

std::vector<BackdropItem> read_backdrop(const Node& node, const fs::path& folder) {
  std::vector<BackdropItem> items;
  std::map<std::string, std::string> names;  // name -> path of its first use
  for (const Node& n : node.elements(kBackdropExpected)) {
    items.push_back(read_item(n, folder));
    const std::string path = n.path() + ".name";
    if (const auto [it, fresh] = names.emplace(items.back().name, path); !fresh) {
      json_reader::fail(n.file(), path,
                        "duplicate backdrop name \"" + it->first + "\" (also " + it->second + ")",
                        "allowed a name that no other backdrop item uses");
    }
  }
  return items;
}

std::vector<InstrumentDrawable> read_instruments(const Node& node) {
  std::vector<InstrumentDrawable> list;
  for (const Node& n : node.elements(kInstrumentsExpected)) {
    n.expect_object(kInstrumentsExpected, {"name", "shape", "position", "axis"});
    InstrumentDrawable d;
    d.name = n.at("name", "a non-empty string").text();
    d.shape = read_tool_shape(
        n.at("shape", "a tool shape {\"type\": \"capsule\", \"radius\": m, \"length\": m}"));
    d.pose.position = n.vec3("position", Limits::any(), "m");
    const Vec3 axis = n.vec3("axis", Limits::any(), "");
    if (axis.norm() == 0) {
      n.at("axis", "").fail("zero axis", "allowed a non-zero direction [x, y, z]");
    }
    d.pose.axis = axis.normalized();
    list.push_back(d);
  }
  return list;
}

}  // namespace phyxel
