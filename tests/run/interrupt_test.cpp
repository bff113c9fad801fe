// `phyxel run` stopped by SIGINT or SIGTERM, end to end: the binary runs as a child process,
// gets the signal at a random time once it is simulating, and must leave a whole output folder
// (the last state, summary.json saying it was interrupted, no temporary files) and exit with
// 130 or 143. A second SIGINT ends it at once.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <thread>

#include "tests/physics/physics_fixtures.h"

extern char** environ;

namespace phyxel {
namespace {

using Clock = std::chrono::steady_clock;

std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The demo beam (41 x 9 x 9 phyxels) that never comes to rest early and writes its points every
// `every` steps: the first points file says the run loop is going.
std::filesystem::path long_beam_scene(const std::filesystem::path& dir, int every) {
  nlohmann::json scene =
      nlohmann::json::parse(read_file(std::string(PHYXEL_SOURCE_DIR) + "/scenes/beam.json"));
  scene["simulation"].erase("until_rest");
  scene["output"]["every"] = every;
  const auto file = dir / "long_beam.json";
  std::ofstream(file) << scene.dump(2);
  return file;
}
constexpr size_t kBeamPhyxels = 41 * 9 * 9;

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
  std::string log() const { return read_file(log_); }

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

// A whole ASCII .vtp of the scene's points: well-formed (every element closed, in order), the
// point count, every array, 3 finite coordinates per point.
void expect_whole_vtp(const std::filesystem::path& file, size_t points) {
  const std::string text = read_file(file);
  ASSERT_EQ(text.rfind("<?xml", 0), 0u) << file;
  const std::string end = "</VTKFile>\n";
  ASSERT_GE(text.size(), end.size()) << file;
  EXPECT_EQ(text.substr(text.size() - end.size()), end) << file;
  EXPECT_NE(text.find("NumberOfPoints=\"" + std::to_string(points) + "\""), std::string::npos)
      << file;
  for (const std::string tag : {"VTKFile ", "PolyData>", "Piece ", "Points>", "PointData "}) {
    const size_t open = text.find('<' + tag);
    const size_t close = text.find("</" + tag.substr(0, tag.size() - 1) + '>');
    EXPECT_NE(open, std::string::npos) << tag;
    EXPECT_NE(close, std::string::npos) << tag;
    EXPECT_LT(open, close) << tag;
  }
  size_t opened = 0, closed = 0;
  for (size_t at = 0; (at = text.find("<DataArray", at)) != std::string::npos; ++at) ++opened;
  for (size_t at = 0; (at = text.find("</DataArray>", at)) != std::string::npos; ++at) ++closed;
  EXPECT_EQ(opened, closed);
  for (const char* name : {"rest_position", "displacement", "velocity", "von_mises", "flags"})
    EXPECT_NE(text.find("Name=\"" + std::string(name) + "\""), std::string::npos) << name;
  const size_t begin = text.find('>', text.find("<DataArray", text.find("<Points>"))) + 1;
  std::istringstream values(text.substr(begin, text.find("</DataArray>", begin) - begin));
  size_t count = 0;
  for (double v; values >> v; ++count) ASSERT_TRUE(std::isfinite(v)) << file;
  EXPECT_EQ(count, 3 * points) << file;
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
                           const std::vector<std::string>& extra = {}) {
  const auto dir = test::test_output_dir(name);
  const auto out = dir / "out";
  std::filesystem::create_directories(out);
  Child child(long_beam_scene(dir, 50), out, extra);
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
  const nlohmann::json s = nlohmann::json::parse(read_file(out / "summary.json"));
  EXPECT_EQ(s["interrupted"], true);
  EXPECT_EQ(s["non_finite"], false);
  const int64_t steps = s["steps_done"].get<int64_t>();
  EXPECT_GT(steps, 0);
  EXPECT_LT(steps, 10000000);
  char last[64];
  std::snprintf(last, sizeof last, "points_%06lld.vtp", static_cast<long long>(steps));
  EXPECT_TRUE(std::filesystem::exists(out / last)) << last;
  EXPECT_EQ(s["outputs"].back(), last);
  EXPECT_EQ(files_matching(out, "points_", ".vtp").back().filename().string(), std::string(last));
  expect_whole_vtp(out / last, kBeamPhyxels);
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
  const std::string png = read_file(r.out / frame);
  ASSERT_GE(png.size(), 8u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
}

TEST(PhyxelRunInterrupt, SecondSigintExitsAtOnce) {
  const auto dir = test::test_output_dir("interrupt_twice");
  const auto out = dir / "out";
  std::filesystem::create_directories(out);
  Child child(long_beam_scene(dir, 50), out, {});
  ASSERT_TRUE(child.started());
  ASSERT_TRUE(wait_until_simulating(child, out)) << child.log();
  random_pause();
  child.send(SIGINT);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  child.send(SIGINT);  // (or the first one already ended it: 130 as well)
  const auto sent = Clock::now();
  ASSERT_TRUE(child.wait(std::chrono::seconds(60))) << "still running 60 s after two SIGINTs";
  EXPECT_LT(Clock::now() - sent, std::chrono::seconds(10));
  EXPECT_TRUE(WIFEXITED(child.status())) << "ended by signal " << WTERMSIG(child.status());
  EXPECT_EQ(WEXITSTATUS(child.status()), 130) << child.log();
  // Whatever was written before is whole: every points file that is there (a write cut short
  // leaves at most its .tmp).
  for (const auto& file : files_matching(out, "points_", ".vtp"))
    expect_whole_vtp(file, kBeamPhyxels);
}

}  // namespace
}  // namespace phyxel
