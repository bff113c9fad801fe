// `phyxel run` with surgical tools end to end: tools.csv, summary.json tools and haptics,
// the .vtp `contact` array (ASCII and binary), --explain, haptic runs with the scripted device
// and with the reference UDP driver (tools/haptic_udp_client), and the GPU solver against the
// CPU. Every test runs the real binaries in a folder of its own, bounded by --steps, --seconds
// and `timeout`.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "compute/test_env.h"
#include "tests/physics/physics_fixtures.h"
#include "tests/support/support.h"

namespace phyxel {
namespace {

const std::string kClient = PHYXEL_BINARY_DIR "/tools/haptic_udp_client";

using phyxel::test::exit_status;
using phyxel::test::kPhyxel;
using phyxel::test::read_json;
using phyxel::test::read_text;

// Runs a shell command under `timeout` (nothing hangs); returns its exit status.
int shell(const std::string& command, int seconds = 60) {
  const int status =
      std::system(("timeout " + std::to_string(seconds) + " sh -c '" + command + "'").c_str());
  return exit_status(status);
}

// Runs `phyxel ARGS --quiet` with stdout and stderr in DIR; returns the exit status.
struct Ran {
  int code;
  std::string out, err;
};
Ran phyxel(const std::string& args, const std::filesystem::path& dir) {
  const std::string out = (dir / "stdout.txt").string(), err = (dir / "stderr.txt").string();
  const int code = shell(kPhyxel + " " + args + " --quiet >" + out + " 2>" + err);
  return {code, read_text(out), read_text(err)};
}

// A block 2 x 2 x 1 cm (9 x 9 x 5 phyxels, top face at z = 1 cm) fixed at the bottom, and two
// spheres: "probe" comes down over the block's centre (clear of it until t = 0.02 s, its
// bottom 4 mm below the top face at t = 0.06 s), "idle" stays far away.
struct SceneSpec {
  bool tools = true;
  std::string control = "path";  // of the probe
  double touch_t = 0.02, end_t = 0.06;
  std::string format = "binary";
  std::string coupling;  // the probe's "coupling" object, where not empty (haptic control)
};
constexpr double kRadius = 0.003, kTop = 0.01, kDt = 1e-3;
constexpr double kZ0 = 0.017, kZTouch = 0.015, kZEnd = 0.009;

std::string scene_json(const SceneSpec& s) {
  std::ostringstream j;
  j << R"({"simulation": {"dt": 1e-3, "steps": 60, "gravity": [0, 0, 0]},
  "objects": [{"name": "block", "shape": {"type": "box", "min": [0, 0, 0], "max": [0.02, 0.02, 0.01]},
    "spacing": 0.0025,
    "material": {"young": 1e4, "poisson": 0.3, "density": 1000, "damping": 20},
    "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.001]}]}],
  "output": {"every": 20, "format": ")"
    << s.format << "\"}";
  if (s.tools)
    j << R"(, "tools": [
    {"name": "probe", "type": "probe", "control": ")"
      << s.control << R"(", "shape": {"type": "sphere", "radius": 0.003},
     "path": [{"t": 0, "position": [0.01, 0.01, 0.017]},
              {"t": )"
      << s.touch_t << R"(, "position": [0.01, 0.01, 0.015]},
              {"t": )"
      << s.end_t << R"(, "position": [0.01, 0.01, 0.009]}], "friction": 0.2)"
      << (s.coupling.empty() ? "" : ", \"coupling\": " + s.coupling) << R"(},
    {"name": "idle", "type": "probe", "shape": {"type": "sphere", "radius": 0.002},
     "path": [{"t": 0, "position": [0.06, 0.06, 0.06]}]}])";
  j << "}\n";
  return j.str();
}

std::filesystem::path write_scene(const std::filesystem::path& dir, const SceneSpec& s) {
  const auto file = dir / "scene.json";
  std::ofstream(file) << scene_json(s);
  return file;
}

// The probe's path tip height at time t (path control), the keys of SceneSpec{}.
double path_z(double t) {
  const SceneSpec s;
  if (t <= s.touch_t) return kZ0 + (kZTouch - kZ0) * t / s.touch_t;
  if (t >= s.end_t) return kZEnd;
  return kZTouch + (kZEnd - kZTouch) * (t - s.touch_t) / (s.end_t - s.touch_t);
}

std::vector<std::string> split(const std::string& line, char sep = ',') {
  std::vector<std::string> fields;
  std::stringstream ss(line);
  std::string f;
  while (std::getline(ss, f, sep)) fields.push_back(f);
  return fields;
}

// A CSV file: its header line and its rows.
struct Csv {
  std::string header;
  std::vector<std::vector<std::string>> rows;
};
Csv read_csv(const std::filesystem::path& file) {
  Csv csv;
  std::ifstream in(file);
  std::getline(in, csv.header);
  for (std::string line; std::getline(in, line);) csv.rows.push_back(split(line));
  return csv;
}

std::string attribute(const std::string& tag, const std::string& name) {
  const size_t at = tag.find(" " + name + "=\"");
  if (at == std::string::npos) return "";
  const size_t start = at + name.size() + 3;
  return tag.substr(start, tag.find('"', start) - start);
}

// The values of the named DataArray of a .vtp file (ASCII or appended raw binary). For an
// appended array the block's byte count must match its type; the block after the last one must
// end where </AppendedData> starts. Empty when the array is absent.
std::vector<double> vtp_array(const std::string& text, const std::string& name) {
  const size_t at = text.find("Name=\"" + name + "\"");
  if (at == std::string::npos) return {};
  const size_t open = text.rfind("<DataArray", at), close = text.find('>', at);
  const std::string tag = text.substr(open, close - open);
  const std::string type = attribute(tag, "type");
  const size_t width = type == "UInt32" ? 4 : 8;
  std::vector<double> values;
  if (attribute(tag, "format") == "ascii") {
    std::istringstream in(text.substr(close + 1, text.find("</DataArray>", close) - close - 1));
    for (double v; in >> v;) values.push_back(v);
    return values;
  }
  const size_t base = text.find("<AppendedData encoding=\"raw\">\n_");
  EXPECT_NE(base, std::string::npos);
  const size_t data = text.find('_', base) + 1 + std::stoull(attribute(tag, "offset"));
  uint64_t bytes = 0;
  EXPECT_LE(data + sizeof bytes, text.size()) << name;
  if (data + sizeof bytes > text.size()) return {};
  std::memcpy(&bytes, text.data() + data, sizeof bytes);
  EXPECT_EQ(bytes % width, 0u) << name;
  EXPECT_LE(data + sizeof bytes + bytes, text.size()) << name;
  if (data + sizeof bytes + bytes > text.size()) return {};
  for (uint64_t k = 0; k < bytes / width; ++k) {
    const char* p = text.data() + data + sizeof bytes + k * width;
    if (type == "UInt32") {
      uint32_t v;
      std::memcpy(&v, p, 4);
      values.push_back(v);
    } else if (type == "Int64") {
      int64_t v;
      std::memcpy(&v, p, 8);
      values.push_back(static_cast<double>(v));
    } else {
      double v;
      std::memcpy(&v, p, 8);
      values.push_back(v);
    }
  }
  if (name == "offsets") {  // the last block: the appended data ends right after it
    EXPECT_EQ(text.compare(data + sizeof bytes + bytes, 16, "\n</AppendedData>"), 0);
  }
  return values;
}

size_t vtp_points(const std::string& text) {
  return std::stoul(attribute(text.substr(text.find("<Piece"), 200), "NumberOfPoints"));
}

// The last points file the summary lists.
std::filesystem::path last_vtp(const std::filesystem::path& dir, const nlohmann::json& summary) {
  std::string last;
  for (const auto& f : summary["outputs"]) {
    const std::string name = f.get<std::string>();
    if (name.rfind("points_", 0) == 0) last = std::max(last, name);
  }
  return dir / last;
}

// Checks the contact array of a run's last .vtp: one 0/1 value per point, some 1s.
void expect_contact_array(const std::filesystem::path& vtp) {
  const std::string text = read_text(vtp);
  const size_t n = vtp_points(text);
  const std::vector<double> contact = vtp_array(text, "contact");
  ASSERT_EQ(contact.size(), n) << vtp;
  EXPECT_TRUE(
      std::all_of(contact.begin(), contact.end(), [](double c) { return c == 0 || c == 1; }));
  EXPECT_GT(std::count(contact.begin(), contact.end(), 1.0), 0) << vtp;
  // The arrays around it are intact too.
  EXPECT_EQ(vtp_array(text, "flags").size(), n);
  EXPECT_EQ(vtp_array(text, "displacement").size(), 3 * n);
  EXPECT_EQ(vtp_array(text, "offsets").size(), n);
}

TEST(ToolsRun, PathProbeWritesToolsCsvSummaryAndContact) {
  const auto dir = test::test_output_dir("tools_run_path");
  const auto scene = write_scene(dir, SceneSpec{});
  const Ran r = phyxel("run " + scene.string() + " --threads 1 --out " + dir.string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;

  const Csv csv = read_csv(dir / "tools.csv");
  EXPECT_EQ(
      csv.header,
      "step,t,name,px,py,pz,ax,ay,az,fx,fy,fz,contacts,cut_force,theta,f_l,f_p,depth,f_cx,f_cy,"
      "f_cz");
  ASSERT_EQ(csv.rows.size(), 2u * 60);  // a row per step and tool
  int first_touch = -1;
  for (size_t k = 0; k < csv.rows.size(); ++k) {
    const auto& row = csv.rows[k];
    ASSERT_EQ(row.size(), 21u) << k;
    // Probes do not cut: their cutting-force columns are zero.
    for (int c = 13; c < 21; ++c) EXPECT_EQ(std::stod(row[c]), 0.0) << k << " " << c;
    const int step = std::stoi(row[0]);
    const double t = std::stod(row[1]);
    EXPECT_EQ(step, static_cast<int>(k / 2) + 1) << k;
    EXPECT_NEAR(t, step * kDt, 1e-12) << k;
    EXPECT_EQ(row[2], k % 2 == 0 ? "probe" : "idle") << k;
    for (int c = 3; c < 12; ++c) EXPECT_TRUE(std::isfinite(std::stod(row[c]))) << k << " " << c;
    const int contacts = std::stoi(row[12]);
    if (row[2] == "idle") {
      EXPECT_EQ(contacts, 0) << k;
      EXPECT_EQ(std::stod(row[11]), 0.0) << k;
      continue;
    }
    // The tip follows the path, interpolated linearly between the keys.
    EXPECT_NEAR(std::stod(row[3]), 0.01, 1e-12) << k;
    EXPECT_NEAR(std::stod(row[5]), path_z(t), 1e-9) << k;
    const double depth = kTop - (std::stod(row[5]) - kRadius);  // below the top face
    if (depth < -0.001) {
      EXPECT_EQ(contacts, 0) << "before the first touch, step " << step;
      EXPECT_EQ(std::stod(row[11]), 0.0) << step;
    }
    if (depth > 0.002) {
      EXPECT_GT(contacts, 0) << "pressed 2 mm in, step " << step;
      EXPECT_GT(std::stod(row[11]), 0.0) << "the tissue pushes the probe up, step " << step;
    }
    if (contacts > 0 && first_touch < 0) first_touch = step;
  }
  // Step 40: t = 0.04, halfway between the keys at 0.02 s (z 0.015) and 0.06 s (z 0.009).
  EXPECT_NEAR(std::stod(csv.rows[2 * 39][5]), 0.012, 1e-9);
  EXPECT_GT(first_touch, 20);

  const nlohmann::json s = read_json(dir / "summary.json");
  ASSERT_TRUE(s.contains("tools")) << s.dump(2);
  ASSERT_EQ(s["tools"].size(), 2u);
  const auto& probe = s["tools"][0];
  EXPECT_EQ(probe["name"], "probe");
  EXPECT_EQ(s["tools"][1]["name"], "idle");
  ASSERT_EQ(probe["force"].size(), 3u);
  for (const auto& f : probe["force"]) EXPECT_TRUE(std::isfinite(f.get<double>()));
  EXPECT_GT(probe["force"][2].get<double>(), 0.0);
  EXPECT_GE(probe["max_force"].get<double>(), probe["force"][2].get<double>());
  EXPECT_GT(probe["contacts"].get<int>(), 0);
  EXPECT_GE(probe["max_contacts"].get<int>(), probe["contacts"].get<int>());
  EXPECT_EQ(s["tools"][1]["max_contacts"], 0);
  EXPECT_EQ(s["tools"][1]["max_force"], 0.0);
  // The summary's force is the last step's row.
  EXPECT_NEAR(probe["force"][2].get<double>(), std::stod(csv.rows[2 * 59][11]),
              1e-6 * probe["max_force"].get<double>());
  EXPECT_EQ(probe["contacts"].get<int>(), std::stoi(csv.rows[2 * 59][12]));
  ASSERT_TRUE(s.contains("real_time_factor"));
  EXPECT_GT(s["real_time_factor"].get<double>(), 0.0);
  EXPECT_FALSE(s.contains("haptics"));
  expect_contact_array(last_vtp(dir, s));  // binary
}

TEST(ToolsRun, AsciiPointsHaveTheContactArray) {
  const auto dir = test::test_output_dir("tools_run_ascii");
  SceneSpec spec;
  spec.format = "ascii";
  const auto scene = write_scene(dir, spec);
  const Ran r = phyxel("run " + scene.string() + " --threads 1 --out " + dir.string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  expect_contact_array(last_vtp(dir, read_json(dir / "summary.json")));
}

TEST(ToolsRun, SceneWithoutToolsHasNoToolOutputs) {
  const auto dir = test::test_output_dir("tools_run_none");
  SceneSpec spec;
  spec.tools = false;
  const auto scene = write_scene(dir, spec);
  for (const char* format : {"ascii", "binary"}) {
    spec.format = format;
    write_scene(dir, spec);
    const auto out = dir / format;
    std::filesystem::create_directories(out);
    const Ran r =
        phyxel("run " + scene.string() + " --steps 10 --threads 1 --out " + out.string(), dir);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out / "tools.csv")) << format;
    const nlohmann::json s = read_json(out / "summary.json");
    EXPECT_FALSE(s.contains("tools")) << format;
    EXPECT_FALSE(s.contains("haptics")) << format;
    const std::string text = read_text(last_vtp(out, s));
    EXPECT_EQ(text.find("Name=\"contact\""), std::string::npos) << format;
    EXPECT_EQ(vtp_array(text, "offsets").size(), vtp_points(text)) << format;
  }
}

TEST(ToolsRun, ExplainListsTheContactAndCutPasses) {
  const auto dir = test::test_output_dir("tools_run_explain");
  const auto with = write_scene(dir, SceneSpec{});
  Ran r = phyxel("run " + with.string() + " --explain --out " + dir.string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("contact        2 tool(s)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("tools.csv"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("contact passes (no tool)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("cutting passes (no scalpel)"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("scalpel(s)"), std::string::npos) << r.out;

  // A scalpel: the cut pass is listed, and not as skipped.
  const std::string scalpel = std::string(PHYXEL_SOURCE_DIR) + "/scenes/scalpel_cut.json";
  r = phyxel("run " + scalpel + " --explain --out " + dir.string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("cut            1 scalpel(s)"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("no scalpel"), std::string::npos) << r.out;

  SceneSpec spec;
  spec.tools = false;
  const auto without = dir / "no_tools.json";
  std::ofstream(without) << scene_json(spec);
  r = phyxel("run " + without.string() + " --explain --out " + dir.string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const size_t not_recorded = r.out.find("not recorded:");
  ASSERT_NE(not_recorded, std::string::npos) << r.out;
  const std::string line =
      r.out.substr(not_recorded, r.out.find('\n', not_recorded) - not_recorded);
  EXPECT_NE(line.find("contact passes (no tool)"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("tool(s)"), std::string::npos) << r.out;
}

TEST(ToolsRun, AGrasperHoldsAndReportsItsPull) {
  const auto dir = test::test_output_dir("tools_run_grasper");
  const std::string scene = std::string(PHYXEL_SOURCE_DIR) + "/scenes/grasper_tear.json";
  Ran r = phyxel("run " + scene + " --explain --out " + dir.string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("grasp          1 grasper(s)"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("no grasper"), std::string::npos) << r.out;
  // 15 ms: the jaws close at 5 ms and pull.
  r = phyxel("run " + scene + " --steps 15 --threads 1 --render none --out " + dir.string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json s = read_json(dir / "summary.json");
  ASSERT_EQ(s["tools"].size(), 1u);
  const auto& t = s["tools"][0];
  EXPECT_GT(t["held"].get<int>(), 100);
  EXPECT_EQ(t["max_held"], t["held"]);
  EXPECT_GT(t["max_pull_force"].get<double>(), 0.001);
  // A scene without a grasper records none of it.
  const auto without = write_scene(dir, SceneSpec{});
  r = phyxel("run " + without.string() + " --explain --out " + dir.string(), dir);
  EXPECT_NE(r.out.find("grasp passes (no grasper)"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("grasper(s)"), std::string::npos) << r.out;
}

// The haptics entry of a summary: one loop, `device`, ticks and finite period statistics.
void expect_haptics(const nlohmann::json& s, const std::string& device_prefix) {
  ASSERT_TRUE(s.contains("haptics")) << s.dump(2);
  ASSERT_EQ(s["haptics"].size(), 1u);  // the probe only; "idle" follows its path
  const auto& h = s["haptics"][0];
  EXPECT_EQ(h["tool"], "probe");
  EXPECT_EQ(h["device"].get<std::string>().rfind(device_prefix, 0), 0u) << h["device"];
  EXPECT_GT(h["ticks"].get<int64_t>(), 0);
  for (const char* key :
       {"period_mean_ms", "period_p99_ms", "period_max_ms", "max_force_jump", "max_hand_force"}) {
    ASSERT_TRUE(h[key].is_number()) << key;
    EXPECT_TRUE(std::isfinite(h[key].get<double>())) << key;
  }
  EXPECT_GT(h["period_mean_ms"].get<double>(), 0.0);
  EXPECT_GT(h["snapshots"].get<int64_t>(), 0);
  // The block's tissue: a tenth of its p-wave speed (E 1e4 Pa, nu 0.3, 1000 kg/m^3: 3.669 m/s).
  EXPECT_NEAR(h["top_speed"].get<double>(), 0.3669, 1e-4);
  EXPECT_GE(h["speed_limited_ticks"].get<int64_t>(), 0);
  EXPECT_TRUE(s.contains("max_lag_seconds"));
}

TEST(ToolsRun, ScriptedHapticRunIsPacedToTheWallClock) {
  const auto dir = test::test_output_dir("tools_run_scripted");
  SceneSpec spec;
  spec.control = "haptic";
  const auto scene = write_scene(dir, spec);
  const auto start = std::chrono::steady_clock::now();
  const Ran r = phyxel("run " + scene.string() + " --steps 300 --threads 1 --out " + dir.string(),
                       dir);  // 0.3 s simulated
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_GE(wall, 0.25);
  const nlohmann::json s = read_json(dir / "summary.json");
  EXPECT_EQ(s["steps_done"], 300);
  EXPECT_NEAR(s["simulated_time"].get<double>(), 0.3, 1e-9);
  EXPECT_GE(s["wall_seconds"].get<double>(), 0.25);
  const double factor = s["real_time_factor"].get<double>();
  EXPECT_GT(factor, 0.0);
  EXPECT_LE(factor, 1.05);  // paced: never ahead of the wall clock
  expect_haptics(s, "scripted");
  // The scripted device replays the path: the probe ends pressed into the block.
  EXPECT_EQ(read_csv(dir / "tools.csv").rows.size(), 2u * 300);
  EXPECT_GT(s["tools"][0]["max_contacts"].get<int>(), 0);
  expect_contact_array(last_vtp(dir, s));
}

// A top speed below the path's (0.1 and 0.15 m/s): the tool is held to it, lags its device and
// the run says so, whatever the physics' rate (the device is faster in simulated time still).
TEST(ToolsRun, AHapticToolHeldToItsTopSpeedSaysSo) {
  const auto dir = test::test_output_dir("tools_run_top_speed");
  SceneSpec spec;
  spec.control = "haptic";
  spec.coupling = R"({"max_speed": 0.01})";
  const auto scene = write_scene(dir, spec);
  const Ran r =
      phyxel("run " + scene.string() + " --steps 100 --threads 1 --out " + dir.string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json s = read_json(dir / "summary.json");
  const auto& h = s["haptics"][0];
  EXPECT_EQ(h["top_speed"].get<double>(), 0.01);
  EXPECT_GT(h["speed_limited_ticks"].get<int64_t>(), 0);
  EXPECT_NE(r.err.find("tool 'probe' was held to its top speed, 0.01 m/s in simulated time"),
            std::string::npos)
      << r.err;
  // 0.1 s at most 0.01 m/s: at most 1 mm down from 17 mm.
  const Csv trace = read_csv(dir / "tools.csv");
  for (const auto& row : trace.rows) {
    if (row[2] == "probe") {
      EXPECT_GT(std::stod(row[5]), kZ0 - 0.001 - 1e-9) << row[0];
    }
  }
}

TEST(ToolsRun, BadHapticDevicesAreOneLineErrors) {
  const auto dir = test::test_output_dir("tools_run_bad_device");
  SceneSpec spec;
  spec.control = "haptic";
  const auto scene = write_scene(dir, spec);
  for (const std::string device : {"bogus", "udp:0", "udp:99999", "udp:", "udp:12ab"}) {
    const Ran r = phyxel("run " + scene.string() + " --steps 5 --haptic-device " + device +
                             " --out " + (dir / "out").string(),
                         dir);
    EXPECT_EQ(r.code, 2) << device << ": " << r.err;  // bad usage
    EXPECT_NE(r.err.find("--haptic-device " + device), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "out" / "summary.json")) << device;
  }
}

// A UDP port on 127.0.0.1 free a moment ago: bound to port 0, read back, closed.
int free_udp_port() {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  EXPECT_GE(fd, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = 0;
  EXPECT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  socklen_t len = sizeof addr;
  EXPECT_EQ(::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len), 0);
  ::close(fd);
  return ntohs(addr.sin_port);
}

TEST(ToolsRun, TheReferenceUdpClientDrivesTheProbeAndFeelsTheTissue) {
  const auto dir = test::test_output_dir("tools_run_udp");
  SceneSpec spec;
  spec.control = "haptic";
  spec.touch_t = 0.3;  // the client replays this path over 1 s
  spec.end_t = 0.8;
  const auto scene = write_scene(dir, spec);
  const int port = free_udp_port();
  ASSERT_GT(port, 0);
  const std::string d = dir.string(), log = (dir / "forces.csv").string();
  // phyxel (1.5 s paced) in the background; the client starts once phyxel has bound its port
  // and replays the probe's path for 1 s.
  const std::string command =
      "( timeout 30 " + kPhyxel + " run " + scene.string() +
      " --haptic-device udp:" + std::to_string(port) + " --steps 1500 --threads 1 --quiet --out " +
      d + " >" + d + "/stdout.txt 2>" + d + "/stderr.txt; echo $? >" + d +
      "/phyxel_rc ) & sleep 0.5; timeout 20 " + kClient + " --port " + std::to_string(port) +
      " --scene " + scene.string() + " --seconds 1 --log " + log + " >" + d +
      "/client.txt 2>&1; echo $? >" + d + "/client_rc; wait";
  ASSERT_EQ(shell(command, 60), 0);
  ASSERT_EQ(read_text(dir / "phyxel_rc"), "0\n") << read_text(dir / "stderr.txt");
  EXPECT_EQ(read_text(dir / "client_rc"), "0\n") << read_text(dir / "client.txt");
  EXPECT_NE(read_text(dir / "client.txt").find("sent 1000 poses"), std::string::npos)
      << read_text(dir / "client.txt");

  const Csv forces = read_csv(log);
  EXPECT_EQ(forces.header, "t,seq,fx,fy,fz,status");
  ASSERT_GT(forces.rows.size(), 100u);
  double max_fz = 0;
  int in_contact = 0;
  for (const auto& row : forces.rows) {
    ASSERT_EQ(row.size(), 6u);
    for (int c = 2; c < 5; ++c) ASSERT_TRUE(std::isfinite(std::stod(row[c])));
    max_fz = std::max(max_fz, std::stod(row[4]));
    in_contact += std::stoi(row[5]) & 1;
  }
  EXPECT_GT(in_contact, 0) << "the probe never touched the block";
  EXPECT_GT(max_fz, 0.01) << "the hand never felt the tissue push up";

  const nlohmann::json s = read_json(dir / "summary.json");
  expect_haptics(s, "udp");
  EXPECT_GT(s["tools"][0]["max_contacts"].get<int>(), 0);
  // The driver moved the probe down: it ended well below its first pose.
  const Csv trace = read_csv(dir / "tools.csv");
  ASSERT_EQ(trace.rows.size(), 2u * 1500);
  EXPECT_LT(std::stod(trace.rows[2 * 1499][5]), kZTouch);
}

// The GPU computes in float32. tests/gpu_solver/contact_test.cpp bounds the float32 tool force
// by 2e-4 of its peak per substep (a phyxel entering contact one substep apart costs about
// 1e-2); the summary's force is the last step's mean over its substeps and max_force the peak
// of those means, so the same bound holds for them. Measured on lavapipe: 2e-7 of the peak.
constexpr double kGpuForceTol = 2e-4;

TEST(ToolsRun, GpuProbeForceMatchesTheCpu) {
  gpu::ContextOptions context;
  try {
    context = gpu::test_context_options();  // lavapipe: sets VK_DRIVER_FILES for the child
  } catch (const VulkanError& e) {
    GTEST_SKIP() << e.what();
  }
  const auto dir = test::test_output_dir("tools_run_gpu");
  const auto scene = write_scene(dir, SceneSpec{});
  const Ran cpu =
      phyxel("run " + scene.string() + " --threads 1 --out " + (dir / "cpu").string(), dir);
  ASSERT_EQ(cpu.code, 0) << cpu.err;
  const Ran gpu =
      phyxel("run " + scene.string() + " --device " + context.device +
                 (context.validation ? " --validate" : "") + " --out " + (dir / "gpu").string(),
             dir);
  ASSERT_EQ(gpu.code, 0) << gpu.err;
  const nlohmann::json c = read_json(dir / "cpu" / "summary.json");
  const nlohmann::json g = read_json(dir / "gpu" / "summary.json");
  ASSERT_TRUE(g.contains("tools")) << g.dump(2);
  const auto &ct = c["tools"][0], &gt = g["tools"][0];
  const double scale = ct["max_force"].get<double>();
  ASSERT_GT(scale, 0.0);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(gt["force"][k].get<double>(), ct["force"][k].get<double>(), kGpuForceTol * scale)
        << k;
  EXPECT_NEAR(gt["max_force"].get<double>(), scale, kGpuForceTol * scale);
  // A phyxel at the edge of the probe may touch in float32 and not in double (the parity
  // tests check the phyxels with a force above 1e-3 of the peak): one apart at most.
  EXPECT_NEAR(gt["contacts"].get<double>(), ct["contacts"].get<double>(), 1);
  EXPECT_NEAR(gt["max_contacts"].get<double>(), ct["max_contacts"].get<double>(), 1);
  EXPECT_GT(gt["max_contacts"].get<int>(), 0);
  expect_contact_array(last_vtp(dir / "gpu", g));
}

}  // namespace
}  // namespace phyxel
