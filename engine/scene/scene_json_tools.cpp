// Scene files: the `tools` key (docs/scene-format.md, "tools"): surgical instruments with their
// rigid shape, path of keyframes, friction and control (engine/scene/tool_desc.h).
#include "engine/scene/scene_json_tools.h"

#include <algorithm>
#include <limits>
#include <map>
#include <string>
#include <string_view>

namespace phyxel {
namespace {

using json_reader::Limits;
using json_reader::Node;

constexpr std::string_view kToolsExpected = "an array of tool objects";
constexpr std::string_view kToolExpected =
    "a tool object {\"name\": \"probe\", \"type\": \"probe\", \"shape\": {...}, \"path\": "
    "[...], ...}";
constexpr std::string_view kToolShapeExpected =
    "a tool shape {\"type\": \"sphere\" | \"capsule\", \"radius\": m, \"length\": m}";
constexpr std::string_view kPathExpected =
    "an array of one or more path keys {\"t\": s, \"position\": [x, y, z], \"axis\": [x, y, z]}";
constexpr std::string_view kKeyExpected =
    "a path key {\"t\": s, \"position\": [x, y, z], \"axis\": [x, y, z]}";
constexpr std::string_view kBladeExpected =
    "a blade {\"length\": m, \"edge\": [x, y, z], \"reach\": m, \"stiffness\": N/m^3}";
constexpr std::string_view kSuctionExpected =
    "a suction object {\"pressure\": Pa, \"reach\": m, \"flow_speed\": m/s, \"interval\": s, "
    "\"from\": s, \"until\": s}";
constexpr std::string_view kGraspExpected =
    "a grasp object {\"reach\": m, \"from\": s, \"until\": s}";
constexpr std::string_view kCouplingExpected =
    "a coupling object {\"stiffness\": N/m, \"damping\": N s/m, \"mass\": kg, \"max_force\": N, "
    "\"max_speed\": m/s}";

// Coulomb coefficients of instruments on tissue are well below 1; above this a value is a typo.
constexpr double kMaxFriction = 10;

// Surgical aspirators pull with up to about 80 kPa below the atmosphere; above 1 MPa a value is
// a typo.
constexpr double kMaxSuctionPressure = 1e6;
// The air in an aspirator's tube moves at tens of m/s; above this a value is a typo.
constexpr double kMaxFlowSpeed = 100;
// An aspirator that looks less often than once a second aspirates nothing a surgeon would see.
constexpr double kMaxAspirationInterval = 1;

// Cutting forces of scalpels in soft tissue are a few newtons; above this a value is a typo.
constexpr double kMaxCutForce = 1e3;
// A tool's cycle ("repeat"), s.
constexpr double kMinRepeat = 1e-6, kMaxRepeat = 1e6;
// A repeating path's shift per cycle ("repeat_shift"), m: at most this along each axis.
constexpr double kMaxRepeatShift = 1;

ToolDesc::Type read_type(const Node& node) {
  const std::string type = node.choice({"probe", "scalpel", "suction", "grasper"});
  return type == "scalpel"   ? ToolDesc::Type::Scalpel
         : type == "suction" ? ToolDesc::Type::Suction
         : type == "grasper" ? ToolDesc::Type::Grasper
                             : ToolDesc::Type::Probe;
}

// The blade of a scalpel: its edge made perpendicular to the axis of the path's first key.
Blade read_blade(const Node& node, const Vec3& first_axis) {
  node.expect_object(kBladeExpected, {"length", "edge", "reach", "stiffness"});
  Blade b;
  b.length = node.number("length", Limits::above(0), "m");
  b.reach = node.number_or("reach", 0.0, Limits::at_least(0), "m");
  b.stiffness = node.number_or("stiffness", kDefaultEdgeStiffness, Limits::at_least(0), "N/m^3");
  const Vec3 edge = node.vec3("edge", Limits::any(), "");
  const Vec3 across = edge - edge.dot(first_axis) * first_axis;
  if (!(across.norm() > 1e-6 * edge.norm())) {
    node.at("edge", "")
        .fail(edge.isZero(0) ? "zero edge" : "edge along the tool's axis",
              "allowed a direction [x, y, z] not parallel to the axis of path[0] (the way the "
              "sharp side faces; its part across the axis is used)");
  }
  b.edge = across.stableNormalized();
  b.reference_axis = first_axis;
  return b;
}

// An action's `until` (s): after `from`; infinity where the key is absent (`open_ended` says
// what that means).
double read_until(const Node& node, double from, const char* open_ended) {
  const auto until = node.find("until");
  if (!until) return std::numeric_limits<double>::infinity();
  const double t = until->number(Limits::at_least(0), "s");
  if (!(t > from))
    until->fail("until = " + json_reader::format_number(t) +
                    " is not after from = " + json_reader::format_number(from),
                std::string("allowed until > from (s), or no until (") + open_ended + ")");
  return t;
}

// An aspirator's action: pressure and reach required, on during [from, until).
Suction read_suction(const Node& node) {
  node.expect_object(kSuctionExpected,
                     {"pressure", "reach", "flow_speed", "interval", "from", "until"});
  Suction s;
  s.pressure = node.number("pressure", {0, kMaxSuctionPressure, false, true}, "Pa");
  s.reach = node.number("reach", Limits::above(0), "m");
  s.flow_speed = node.number_or("flow_speed", s.flow_speed, {0, kMaxFlowSpeed, false, true}, "m/s");
  s.interval =
      node.number_or("interval", s.interval, {0, kMaxAspirationInterval, false, true}, "s");
  s.from = node.number_or("from", 0.0, Limits::at_least(0), "s");
  s.until = read_until(node, s.from, "on to the end");
  return s;
}

// A grasper's jaws: reach required, closed during [from, until).
Grasp read_grasp(const Node& node) {
  node.expect_object(kGraspExpected, {"reach", "from", "until"});
  Grasp g;
  g.reach = node.number("reach", Limits::above(0), "m");
  g.from = node.number_or("from", 0.0, Limits::at_least(0), "s");
  g.until = read_until(node, g.from, "held to the end");
  return g;
}

}  // namespace

// Declared in scene_json_tools.h (render.instruments use it too).
ToolShape read_tool_shape(const Node& node) {
  node.expect_object(kToolShapeExpected, {"type", "radius", "length"});
  const std::string type =
      node.at("type", "\"sphere\" or \"capsule\"").choice({"sphere", "capsule"});
  ToolShape s;
  if (type == "sphere") {
    node.expect_object("a sphere tool shape", {"type", "radius"});
    s.type = ToolShape::Type::Sphere;
    s.radius = node.number("radius", Limits::above(0), "m");
  } else {
    node.expect_object("a capsule tool shape", {"type", "radius", "length"});
    s.type = ToolShape::Type::Capsule;
    s.radius = node.number("radius", Limits::above(0), "m");
    s.length = node.number("length", Limits::above(0), "m");
  }
  return s;
}

namespace {

// The keys of a path: t strictly increasing, the axis non-zero and stored as a unit vector.
std::vector<ToolKey> read_path(const Node& node) {
  const std::vector<Node> keys = node.elements(kPathExpected);
  if (keys.empty()) node.fail("empty array", "allowed " + std::string(kPathExpected));
  std::vector<ToolKey> path;
  for (size_t i = 0; i < keys.size(); ++i) {
    const Node& k = keys[i];
    k.expect_object(kKeyExpected, {"t", "position", "axis"});
    ToolKey key;
    key.t = k.number("t", Limits::at_least(0), "s");
    if (!path.empty() && !(key.t > path.back().t)) {
      k.at("t", "").fail("t = " + json_reader::format_number(key.t) + " is not greater than t = " +
                             json_reader::format_number(path.back().t) + " of path[" +
                             std::to_string(i - 1) + "]",
                         "allowed strictly increasing t along the path, t >= 0 (s)");
    }
    key.position = k.vec3("position", Limits::any(), "m");
    key.axis = k.vec3_or("axis", Vec3::UnitZ(), Limits::any(), "");
    if (key.axis.isZero(0)) {
      k.at("axis", "")
          .fail("zero axis",
                "allowed a non-zero direction [x, y, z] (the shaft, from the tip; "
                "it is normalised)");
    }
    // Stable: components near the limits of double neither underflow nor overflow the norm.
    key.axis = key.axis.stableNormalized();
    path.push_back(key);
  }
  return path;
}

CouplingSettings read_coupling(const Node& node) {
  node.expect_object(kCouplingExpected, {"stiffness", "damping", "mass", "max_force", "max_speed"});
  CouplingSettings c;
  c.stiffness = node.number_or("stiffness", c.stiffness, Limits::above(0), "N/m");
  c.damping = node.number_or("damping", c.damping, Limits::at_least(0), "N s/m");
  c.mass = node.number_or("mass", c.mass, Limits::above(0), "kg");
  c.max_force = node.number_or("max_force", c.max_force, Limits::above(0), "N");
  if (const auto speed = node.find("max_speed"))
    c.max_speed = speed->number(Limits::above(0), "m/s");
  return c;
}

// "repeat": a path tool's cycle (s): at least its path's length, the path ending where it began.
void read_repeat(const Node& node, ToolDesc& tool) {
  tool.repeat = node.number(json_reader::Limits{kMinRepeat, kMaxRepeat, true, true}, "s");
  if (tool.control == ToolDesc::Control::Haptic)
    node.fail("\"repeat\" applies only to a path tool", "remove it or set \"control\": \"path\"");
  const ToolKey &first = tool.path.front(), &last = tool.path.back();
  if (last.t > tool.repeat)
    node.fail("repeat = " + std::to_string(tool.repeat) + " s is shorter than the path (" +
                  std::to_string(last.t) + " s)",
              "a cycle at least as long as the path's last key time");
  if (last.position != first.position || last.axis != first.axis)
    node.fail("a repeating path must end where it begins",
              "a last key with the first key's position and axis");
}

// "repeat_shift": the path moved by this much at each new cycle; only with "repeat".
void read_repeat_shift(const Node& node, ToolDesc& tool) {
  if (tool.repeat <= 0)
    node.fail("\"repeat_shift\" applies only to a repeating path",
              "add \"repeat\": s (the cycle) or remove it");
  tool.repeat_shift = node.vec3({-kMaxRepeatShift, kMaxRepeatShift, true, true}, "m");
}

ToolDesc read_tool(const Node& node) {
  node.expect_object(kToolExpected,
                     {"name", "type", "shape", "path", "friction", "control", "coupling", "blade",
                      "cut_force_threshold", "suction", "grasp", "repeat", "repeat_shift"});
  ToolDesc tool;
  tool.name = node.at("name", "a non-empty string").text();
  tool.type = read_type(node.at("type", "\"probe\", \"scalpel\", \"suction\" or \"grasper\""));
  tool.shape = read_tool_shape(node.at("shape", kToolShapeExpected));
  tool.path = read_path(node.at("path", kPathExpected));
  if (tool.type == ToolDesc::Type::Scalpel) {
    tool.blade = read_blade(node.at("blade", kBladeExpected), tool.path.front().axis);
    tool.blade.threshold =
        node.number_or("cut_force_threshold", 0.0, {0, kMaxCutForce, true, true}, "N");
  } else {
    for (const char* key : {"blade", "cut_force_threshold"}) {
      if (const auto extra = node.find(key)) {
        extra->fail(std::string("\"") + key + "\" applies only to a scalpel",
                    "allowed only with \"type\": \"scalpel\"; remove it or change the type");
      }
    }
  }
  if (tool.type == ToolDesc::Type::Suction) {
    tool.suction = read_suction(node.at("suction", kSuctionExpected));
  } else if (const auto extra = node.find("suction")) {
    extra->fail("\"suction\" applies only to a suction tool",
                "allowed only with \"type\": \"suction\"; remove it or change the type");
  }
  if (tool.type == ToolDesc::Type::Grasper) {
    tool.grasp = read_grasp(node.at("grasp", kGraspExpected));
  } else if (const auto extra = node.find("grasp")) {
    extra->fail("\"grasp\" applies only to a grasper",
                "allowed only with \"type\": \"grasper\"; remove it or change the type");
  }
  tool.friction = node.number_or("friction", 0.0, {0, kMaxFriction, true, true}, "");
  if (const auto control = node.find("control")) {
    tool.control = control->choice({"path", "haptic"}) == "haptic" ? ToolDesc::Control::Haptic
                                                                   : ToolDesc::Control::Path;
  }
  if (const auto repeat = node.find("repeat")) read_repeat(*repeat, tool);
  if (const auto shift = node.find("repeat_shift")) read_repeat_shift(*shift, tool);
  if (const auto coupling = node.find("coupling")) {
    if (tool.control != ToolDesc::Control::Haptic) {
      coupling->fail(
          "\"coupling\" applies only to a haptic tool, and this tool's control is "
          "\"path\"",
          "allowed coupling only with \"control\": \"haptic\"; remove it or set the "
          "control");
    }
    tool.coupling = read_coupling(*coupling);
  }
  return tool;
}

}  // namespace

void read_tools(const Node& root, Scene& scene) {
  const auto tools = root.find("tools");
  if (!tools) return;
  std::map<std::string, std::string> names;  // name -> path of its first use
  for (const Node& node : tools->elements(kToolsExpected)) {
    scene.tools.push_back(read_tool(node));
    const std::string path = node.path() + ".name";
    if (const auto [it, fresh] = names.emplace(scene.tools.back().name, path); !fresh) {
      json_reader::fail(node.file(), path,
                        "duplicate tool name \"" + it->first + "\" (also " + it->second + ")",
                        "allowed a name that no other tool uses");
    }
  }
}

}  // namespace phyxel
