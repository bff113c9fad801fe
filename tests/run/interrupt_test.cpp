// `phyxel run` stopped by SIGINT or SIGTERM, end to end: the binary runs as a child process,
// gets the signal at a random time once it is simulating, and must leave a whole output folder
// (the last state, summary.json saying it was interrupted, no temporary files) and exit with
// 130 or 143. A second SIGINT ends it at once.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <thread>

#include "tests/physics/physics_fixtures.h"
#include "tests/support/support.h"

extern char** environ;

namespace phyxel {
namespace {

using Clock = std::chrono::steady_clock;

using phyxel::test::read_text;

// scenes/NAME as a run that never comes to rest early and writes ASCII points every `every`
// steps: the first points file says the run loop is going.
std::filesystem::path long_scene(const std::filesystem::path& dir, const std::string& name,
                                 int every) {
  nlohmann::json scene =
      nlohmann::json::parse(read_text(std::string(PHYXEL_SOURCE_DIR) + "/scenes/" + name));
  scene["simulation"].erase("until_rest");
  scene["output"]["every"] = every;
  scene["output"]["format"] = "ascii";
  scene.erase("render");
  const auto file = dir / ("long_" + name);
  std::ofstream(file) << scene.dump(2);
  return file;
}

// `phyxel run SCENE --steps 10000000 --out DIR ...` as a child, its output in DIR/../log.txt.
class Child {
 public:
  Child(const std::filesystem::path& scene, const std::filesystem::path& out,
        const std::vector<std::string>& extra) {
    std::vector<std::string> args = {std::string(PHYXEL_BINARY_DIR) + "/app/phyxel",
                                     "run",
                                     scene.string(),
                                     "--steps",
                                     "10000000",
                                     "--threads",
                                     "1",
                                     "--out",
                                     out.string()};
    args.insert(args.end(), extra.begin(), extra.end());
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    log_ = out.parent_path() / (out.filename().string() + "_log.txt");
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log_.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    const int rc = posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) pid_ = -1;
  }
  ~Child() {
    if (pid_ > 0) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  bool started() const { return pid_ > 0; }
  pid_t pid() const { return pid_; }
  void send(int sig) const { kill(pid_, sig); }
  // Whether it is still running.
  bool running() {
    if (pid_ <= 0) return false;
    int status = 0;
    const pid_t r = waitpid(pid_, &status, WNOHANG);
    if (r == 0) return true;
    status_ = status;
    pid_ = -1;
    return false;
  }
  // Waits up to `limit` for it to end; on timeout kills it (SIGKILL) and returns false.
  bool wait(std::chrono::seconds limit) {
    const auto deadline = Clock::now() + limit;
    while (running()) {
      if (Clock::now() > deadline) {
        kill(pid_, SIGKILL);
        waitpid(pid_, nullptr, 0);
        pid_ = -1;
        return false;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return true;
  }
  int status() const { return status_; }
  std::string log() const { return read_text(log_); }

 private:
  pid_t pid_ = -1;
  int status_ = 0;
  std::filesystem::path log_;
};

std::vector<std::filesystem::path> files_matching(const std::filesystem::path& dir,
                                                  const std::string& prefix,
                                                  const std::string& suffix) {
  std::vector<std::filesystem::path> found;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.size() >= prefix.size() + suffix.size() && name.rfind(prefix, 0) == 0 &&
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
      found.push_back(e.path());
  }
  std::sort(found.begin(), found.end());
  return found;
}

// Waits (at most 30 s) for the first points file: the run loop is then going and the signal
// handlers are in place. False if the child ended or nothing came.
bool wait_until_simulating(Child& child, const std::filesystem::path& out) {
  const auto deadline = Clock::now() + std::chrono::seconds(30);
  while (Clock::now() < deadline && child.running()) {
    if (!files_matching(out, "points_", ".vtp").empty()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

// A random pause of up to 300 ms: the signal comes at some point of a step, an output or a check.
void random_pause() {
  std::random_device seed;
  std::uniform_int_distribution<int> ms(0, 300);
  std::this_thread::sleep_for(std::chrono::milliseconds(ms(seed)));
}

// The value of attribute `name` in the tag `tag` ("" if none).
std::string attribute(const std::string& tag, const std::string& name) {
  const size_t at = tag.find(' ' + name + "=\"");
  if (at == std::string::npos) return "";
  const size_t begin = at + name.size() + 3;
  return tag.substr(begin, tag.find('"', begin) - begin);
}

// A whole ASCII .vtp of `points` points, parsed: well-formed (every element closed, in order),
// the point count, every DataArray with points x components finite values (Verts: 0..n-1 and
// 1..n), the arrays the format documents, and positions = rest_position + displacement.
void expect_whole_vtp(const std::filesystem::path& file, size_t points) {
  const std::string text = read_text(file);
  ASSERT_EQ(text.rfind("<?xml", 0), 0u) << file;
  const std::string end = "</VTKFile>\n";
  ASSERT_GE(text.size(), end.size()) << file;
  ASSERT_EQ(text.substr(text.size() - end.size()), end) << file;
  for (const std::string tag :
       {"VTKFile ", "PolyData>", "Piece ", "Points>", "PointData ", "Verts>"}) {
    const size_t open = text.find('<' + tag);
    const size_t close = text.find("</" + tag.substr(0, tag.size() - 1) + '>');
    ASSERT_NE(open, std::string::npos) << file << ": " << tag;
    ASSERT_NE(close, std::string::npos) << file << ": " << tag;
    EXPECT_LT(open, close) << file << ": " << tag;
  }
  const size_t piece = text.find("<Piece ");
  const std::string piece_tag = text.substr(piece, text.find('>', piece) - piece);
  EXPECT_EQ(attribute(piece_tag, "NumberOfPoints"), std::to_string(points)) << file;
  EXPECT_EQ(attribute(piece_tag, "NumberOfVerts"), std::to_string(points)) << file;
  std::map<std::string, std::vector<double>> arrays;  // by Name ("" for the points)
  for (size_t at = 0; (at = text.find("<DataArray", at)) != std::string::npos;) {
    const size_t tag_end = text.find('>', at);
    const size_t close = text.find("</DataArray>", tag_end);
    ASSERT_NE(tag_end, std::string::npos) << file;
    ASSERT_NE(close, std::string::npos) << file << ": a DataArray is not closed";
    const std::string tag = text.substr(at, tag_end - at);
    ASSERT_EQ(attribute(tag, "format"), "ascii") << file;
    const size_t components = std::stoul(attribute(tag, "NumberOfComponents"));
    std::istringstream in(text.substr(tag_end + 1, close - tag_end - 1));
    std::vector<double>& values = arrays[attribute(tag, "Name")];
    for (double v; in >> v;) values.push_back(v);
    EXPECT_TRUE(in.eof()) << file << ": not a number in " << tag;
    EXPECT_EQ(values.size(), points * components) << file << ": " << tag;
    for (double v : values) ASSERT_TRUE(std::isfinite(v)) << file << ": " << tag;
    at = close;
  }
  for (const char* name : {"", "rest_position", "displacement", "velocity", "von_mises", "flags",
                           "connectivity", "offsets"})
    ASSERT_TRUE(arrays.count(name)) << file << ": no array '" << name << "'";
  const auto& x = arrays[""];
  const auto& rest = arrays["rest_position"];
  const auto& u = arrays["displacement"];
  ASSERT_EQ(x.size(), 3 * points);
  ASSERT_EQ(rest.size(), x.size());
  ASSERT_EQ(u.size(), x.size());
  for (size_t i = 0; i < x.size(); ++i)
    ASSERT_NEAR(x[i], rest[i] + u[i], 1e-6 * (1 + std::abs(x[i]))) << file << ": value " << i;
  for (size_t i = 0; i < points; ++i) {
    ASSERT_EQ(arrays["connectivity"][i], static_cast<double>(i)) << file;
    ASSERT_EQ(arrays["offsets"][i], static_cast<double>(i + 1)) << file;
  }
}

void expect_no_temporary_files(const std::filesystem::path& dir) {
  EXPECT_TRUE(files_matching(dir, "", ".tmp").empty()) << dir;
}

struct Interrupted {
  nlohmann::json summary;
  std::filesystem::path out;
};

// One signal: the run ends with 128 + sig and a whole output folder.
Interrupted interrupt_once(const std::string& name, int sig, int expected_status,
                           const std::vector<std::string>& extra = {},
                           const std::string& scene = "beam.json") {
  const auto dir = test::test_output_dir(name);
  const auto out = dir / "out";
  std::filesystem::create_directories(out);
  Child child(long_scene(dir, scene, 50), out, extra);
  EXPECT_TRUE(child.started());
  if (!wait_until_simulating(child, out)) {
    ADD_FAILURE() << "the run did not start simulating:\n" << child.log();
    return {};
  }
  random_pause();
  child.send(sig);
  if (!child.wait(std::chrono::seconds(60))) {
    ADD_FAILURE() << "still running 60 s after the signal (killed):\n" << child.log();
    return {};
  }
  EXPECT_TRUE(WIFEXITED(child.status())) << "ended by signal " << WTERMSIG(child.status());
  EXPECT_EQ(WEXITSTATUS(child.status()), expected_status) << child.log();
  EXPECT_NE(child.log().find("stopped by"), std::string::npos) << child.log();
  expect_no_temporary_files(out);
  const nlohmann::json s = nlohmann::json::parse(read_text(out / "summary.json"));
  EXPECT_EQ(s["interrupted"], true);
  EXPECT_EQ(s["non_finite"], false);
  const int64_t steps = s["steps_done"].get<int64_t>();
  EXPECT_GT(steps, 0);
  EXPECT_LT(steps, 10000000);
  char last[64];
  std::snprintf(last, sizeof last, "points_%06lld.vtp", static_cast<long long>(steps));
  EXPECT_TRUE(std::filesystem::exists(out / last)) << last;
  std::string last_listed;  // the last points file in "outputs" (tools.csv may follow it)
  for (const auto& o : s["outputs"])
    if (o.get<std::string>().rfind("points_", 0) == 0) last_listed = o.get<std::string>();
  EXPECT_EQ(last_listed, last);
  EXPECT_EQ(files_matching(out, "points_", ".vtp").back().filename().string(), std::string(last));
  expect_whole_vtp(out / last, s["phyxels"].get<size_t>());
  return {s, out};
}

TEST(PhyxelRunInterrupt, SigintWritesTheLastStateAndExits130) {
  const Interrupted r = interrupt_once("interrupt_sigint", SIGINT, 130);
  EXPECT_EQ(r.summary["interrupted_by"], "SIGINT");
}

TEST(PhyxelRunInterrupt, SigtermWritesTheLastStateAndExits143) {
  const Interrupted r = interrupt_once("interrupt_sigterm", SIGTERM, 143);
  EXPECT_EQ(r.summary["interrupted_by"], "SIGTERM");
}

TEST(PhyxelRunInterrupt, RenderingRunWritesTheLastFrame) {
  // The renderer runs on any Vulkan device, lavapipe on a machine without a GPU.
  const Interrupted r = interrupt_once("interrupt_render", SIGINT, 130, {"--render", "mono"});
  ASSERT_TRUE(r.summary.contains("steps_done"));
  char frame[64];
  std::snprintf(frame, sizeof frame, "frame_%06lld.png",
                static_cast<long long>(r.summary["steps_done"].get<int64_t>()));
  EXPECT_TRUE(std::filesystem::exists(r.out / frame)) << frame;
  EXPECT_TRUE(std::filesystem::exists(r.out / "frame_000000.png"));
  const std::string png = read_text(r.out / frame);
  ASSERT_GE(png.size(), 8u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
}

TEST(PhyxelRunInterrupt, ToolsCsvIsCompleteUpToTheLastStep) {
  const Interrupted r = interrupt_once("interrupt_tools", SIGINT, 130, {}, "probe_indent.json");
  ASSERT_TRUE(r.summary.contains("steps_done"));
  EXPECT_TRUE(r.summary.contains("tools"));
  const std::string csv = read_text(r.out / "tools.csv");
  ASSERT_FALSE(csv.empty());
  EXPECT_EQ(csv.back(), '\n');
  std::istringstream lines(csv);
  std::string line, last;
  std::getline(lines, line);
  EXPECT_EQ(
      line,
      "step,t,name,px,py,pz,ax,ay,az,fx,fy,fz,contacts,cut_force,theta,f_l,f_p,depth,f_cx,f_cy,"
      "f_cz");
  int64_t rows = 0;
  while (std::getline(lines, line)) {
    EXPECT_EQ(std::count(line.begin(), line.end(), ','), 20) << line;
    last = line;
    ++rows;
  }
  const int64_t steps = r.summary["steps_done"].get<int64_t>();
  EXPECT_EQ(rows, steps);  // one tool: a row per step
  EXPECT_EQ(last.substr(0, last.find(',')), std::to_string(steps));
}

// Waits (at most 30 s) until `sig` sent to process `pid` is no longer pending: it has been
// delivered, so a second one is a second signal (two pending ones of a kind merge into one).
bool wait_delivered(pid_t pid, int sig) {
  const auto deadline = Clock::now() + std::chrono::seconds(30);
  while (Clock::now() < deadline) {
    std::ifstream status("/proc/" + std::to_string(pid) + "/status");
    std::string line;
    bool pending = false;
    while (std::getline(status, line))
      if (line.rfind("ShdPnd:", 0) == 0 || line.rfind("SigPnd:", 0) == 0)
        pending = pending || ((std::stoull(line.substr(7), nullptr, 16) >> (sig - 1)) & 1) != 0;
    if (!status.eof() && !status.good()) return true;  // no such process any more
    if (!pending) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return false;
}

TEST(PhyxelRunInterrupt, SecondSigintExitsAtOnce) {
  const auto dir = test::test_output_dir("interrupt_twice");
  const auto out = dir / "out";
  std::filesystem::create_directories(out);
  // summary.json is written through summary.json.tmp; a FIFO there with no reader blocks the
  // clean stop for good before it writes the summary: the child can then only end through the
  // second signal.
  ASSERT_EQ(mkfifo((out / "summary.json.tmp").c_str(), 0644), 0);
  Child child(long_scene(dir, "beam.json", 50), out, {});
  ASSERT_TRUE(child.started());
  ASSERT_TRUE(wait_until_simulating(child, out)) << child.log();
  random_pause();
  const pid_t pid = child.pid();
  child.send(SIGINT);
  ASSERT_TRUE(wait_delivered(pid, SIGINT)) << "the first SIGINT stayed pending for 30 s";
  EXPECT_TRUE(child.running()) << "the first SIGINT ended the run before its summary:\n"
                               << child.log();
  child.send(SIGINT);
  ASSERT_TRUE(child.wait(std::chrono::seconds(60)))
      << "the second SIGINT did not end the run (killed after 60 s):\n"
      << child.log();
  EXPECT_TRUE(WIFEXITED(child.status())) << "ended by signal " << WTERMSIG(child.status());
  EXPECT_EQ(WEXITSTATUS(child.status()), 130) << child.log();
  EXPECT_FALSE(std::filesystem::exists(out / "summary.json"));
  // Whatever was written before is whole: every points file that is there (a write cut short
  // leaves at most its .tmp).
  const auto written = files_matching(out, "points_", ".vtp");
  EXPECT_FALSE(written.empty());
  for (const auto& file : written) expect_whole_vtp(file, 41 * 9 * 9);  // the demo beam
}

// Waits (at most 30 s) until process `pid` catches `sig` (its handler is installed).
bool wait_catching(pid_t pid, int sig) {
  const auto deadline = Clock::now() + std::chrono::seconds(30);
  while (Clock::now() < deadline) {
    std::ifstream status("/proc/" + std::to_string(pid) + "/status");
    std::string line;
    while (std::getline(status, line))
      if (line.rfind("SigCgt:", 0) == 0 &&
          ((std::stoull(line.substr(7), nullptr, 16) >> (sig - 1)) & 1) != 0)
        return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return false;
}

// Sends SIGTERM to a child once it catches it, or once `line` is in its log; returns the
// seconds from the signal to its end (-1: still running 60 s later, killed).
double terminate_when(Child& child, const std::string& line) {
  const auto deadline = Clock::now() + std::chrono::seconds(60);
  if (!wait_catching(child.pid(), SIGTERM)) return -1;
  while (!line.empty() && child.log().find(line) == std::string::npos && Clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // into the search or the step
  const auto sent = Clock::now();
  child.send(SIGTERM);
  if (!child.wait(std::chrono::seconds(60))) return -1;
  return std::chrono::duration<double>(Clock::now() - sent).count();
}

// 160 000 phyxels with a support radius of 4 spacings (about 270 neighbours each): the
// neighbour search takes seconds on one core. SIGTERM during it (or before it: its first poll
// sees the flag) ends the run at once, writing nothing. The time to stop is recorded.
TEST(PhyxelRunInterrupt, SigtermDuringTheNeighbourSearchStopsIt) {
  const auto dir = test::test_output_dir("interrupt_search");
  const auto out = dir / "out";
  const auto scene = dir / "big.json";
  std::ofstream(scene) << R"({"simulation": {"dt": 1e-4, "steps": 10},
    "objects": [{"name": "block", "shape": {"type": "box", "min": [0, 0, 0], "max": [0.08, 0.08, 0.025]},
      "spacing": 0.001, "support_radius": 0.004,
      "material": {"young": 1e3, "poisson": 0.3, "density": 1000}}],
    "output": {"every": 0}})";
  Child child(scene, out, {});
  ASSERT_TRUE(child.started());
  const double took = terminate_when(child, "");
  ASSERT_GE(took, 0) << child.log();
  RecordProperty("seconds_to_stop", std::to_string(took));
  EXPECT_TRUE(WIFEXITED(child.status())) << "ended by signal " << WTERMSIG(child.status());
  EXPECT_EQ(WEXITSTATUS(child.status()), 143) << child.log();
  EXPECT_NE(child.log().find("stopped during the neighbour search by SIGTERM"), std::string::npos)
      << child.log();
  EXPECT_FALSE(std::filesystem::exists(out / "summary.json"));
}

// A stiff block under a probe and with a tear stress: thousands of substeps per step, seconds
// each. SIGTERM inside the first step ends the run there (tools and tearing cannot go back to
// the step's start): exit 143, a summary of the whole steps done (none), no row, no points of
// the partial step.
TEST(PhyxelRunInterrupt, SigtermInsideALongStepWithToolsStopsIt) {
  const auto dir = test::test_output_dir("interrupt_long_tool_step");
  const auto out = dir / "out";
  const auto scene = dir / "stiff.json";
  std::ofstream(scene) << R"({"simulation": {"dt": 0.02, "steps": 10},
    "objects": [{"name": "block", "shape": {"type": "box", "min": [0, 0, 0], "max": [0.02, 0.02, 0.01]},
      "spacing": 0.002,
      "material": {"young": 1e8, "poisson": 0.3, "density": 1000, "tear_stress": 1e9},
      "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.001]}]}],
    "tools": [{"name": "probe", "type": "probe", "shape": {"type": "sphere", "radius": 0.003},
      "path": [{"t": 0, "position": [0.01, 0.01, 0.014]}, {"t": 0.2, "position": [0.01, 0.01, 0.009]}]}],
    "output": {"every": 0}})";
  Child child(scene, out, {});
  ASSERT_TRUE(child.started());
  const double took = terminate_when(child, "substeps");
  ASSERT_GE(took, 0) << child.log();
  RecordProperty("seconds_to_stop", std::to_string(took));
  EXPECT_TRUE(WIFEXITED(child.status())) << "ended by signal " << WTERMSIG(child.status());
  EXPECT_EQ(WEXITSTATUS(child.status()), 143) << child.log();
  const nlohmann::json s = nlohmann::json::parse(read_text(out / "summary.json"));
  EXPECT_EQ(s["interrupted"], true);
  EXPECT_EQ(s["steps_done"], 0) << "a step takes seconds: the signal came inside the first";
  EXPECT_TRUE(files_matching(out, "points_", ".vtp").empty());
  expect_no_temporary_files(out);
}

}  // namespace
}  // namespace phyxel
