// Runs the built phyxel (PHYXEL_BINARY_DIR "/app/phyxel") on every case of
// tests/data/bad_inputs/cases.json (README.md there) and checks its exit status, its message and
// what it did to the output folder.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "engine/run/checkpoint.h"
#include "tests/support/support.h"

namespace phyxel {
namespace {

namespace fs = std::filesystem;
const fs::path kData = fs::path(PHYXEL_SOURCE_DIR) / "tests/data/bad_inputs";

using phyxel::test::kPhyxel;
using phyxel::test::read_text;

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

fs::path case_dir(const std::string& name) {
  const char* root = std::getenv("PHYXEL_TEST_OUT");
  const fs::path dir = fs::path(root ? root : "/tmp") / "bad_inputs" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// Every file in `dir` (names and contents).
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::directory_iterator(dir))
    files[entry.path().filename().string()] = read_text(entry.path());
  return files;
}

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
    s.replace(at, from.size(), to);
  return s;
}

struct Outcome {
  int status = -1;
  std::string err;
};

// Runs phyxel with `args` under bash (for ulimit -f), stderr to a file.
Outcome run_phyxel(const std::vector<std::string>& args, int ulimit_f, const fs::path& err) {
  // Built by appending: GCC 12 warns falsely (-Wrestrict) about "literal" + std::string&&.
  std::string cmd;
  if (ulimit_f > 0) cmd.append("ulimit -f ").append(std::to_string(ulimit_f)).append("; ");
  cmd.append("exec ").append(shell_quote(kPhyxel));
  for (const std::string& a : args) cmd.append(" ").append(shell_quote(a));
  std::string line = "bash -c ";
  line.append(shell_quote(cmd)).append(" >/dev/null 2>").append(err.string());
  const int status = std::system(line.c_str());
  Outcome out;
  out.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  out.err = read_text(err);
  return out;
}

void run_case(const nlohmann::json& c, size_t index) {
  const std::string name = c.at("case").get<std::string>();
  SCOPED_TRACE("case " + std::to_string(index) + ": " + name);
  const fs::path dir = case_dir("case_" + std::to_string(index));
  const fs::path out = dir / "out";
  fs::create_directories(out);
  // The scene: block.json with the case's values set.
  nlohmann::json scene = nlohmann::json::parse(read_text(kData / "block.json"));
  const nlohmann::json set = c.value("set", nlohmann::json::object());
  for (const auto& [pointer, value] : set.items())
    scene[nlohmann::json::json_pointer(pointer)] = value;
  const fs::path scene_file = dir / "scene.json";
  write_text(scene_file, scene.dump(2));
  // An earlier run's files, and the case's own.
  write_text(out / "summary.json", "{\"steps_done\": 6, \"earlier\": true}\n");
  write_text(out / "tools.csv", "step,t,name\n1,0.0001,probe\n2,0.0002,probe\n");
  write_text(out / "points_000006.vtp", "<VTKFile earlier/>\n");
  const nlohmann::json files = c.value("files", nlohmann::json::object());
  for (const auto& [file, text] : files.items()) write_text(out / file, text.get<std::string>());
  const auto before = snapshot(out);

  std::vector<std::string> args = {"run", "{scene}", "--out", "{out}", "--quiet"};
  if (c.contains("args")) args = c.at("args").get<std::vector<std::string>>();
  for (std::string& a : args)
    a = replace_all(replace_all(a, "{scene}", scene_file.string()), "{out}", out.string());
  const Outcome got = run_phyxel(args, c.value("ulimit_f", 0), dir / "stderr.txt");

  EXPECT_EQ(got.status, c.at("status").get<int>()) << got.err;
  for (const std::string& fragment : c.value("message", std::vector<std::string>{})) {
    EXPECT_NE(got.err.find(fragment), std::string::npos) << "no \"" << fragment << "\" in:\n"
                                                         << got.err;
  }
  if (c.value("one_line", c.at("status").get<int>() != 0)) {
    EXPECT_EQ(std::count(got.err.begin(), got.err.end(), '\n'), 1) << got.err;
  }
  const auto after = snapshot(out);
  if (c.value("unchanged", false)) {
    EXPECT_EQ(after.size(), before.size()) << "files added or removed";
    for (const auto& [file, text] : before) {
      const auto it = after.find(file);
      if (it == after.end()) {
        ADD_FAILURE() << file << " was removed";
      } else {
        EXPECT_EQ(it->second, text) << file << " changed";
      }
    }
  }
  for (const std::string& file : c.value("absent", std::vector<std::string>{})) {
    EXPECT_EQ(after.count(file), 0u) << file << " is still there";
  }
  for (const auto& [file, text] : after) {
    EXPECT_FALSE(file.size() > 4 && file.substr(file.size() - 4) == ".tmp") << file << " left";
  }
}

TEST(BadInputs, EveryCaseOfTheCorpus) {
  const nlohmann::json corpus = nlohmann::json::parse(read_text(kData / "cases.json"));
  const nlohmann::json& cases = corpus.at("cases");
  ASSERT_FALSE(cases.empty());
  for (size_t i = 0; i < cases.size(); ++i) run_case(cases[i], i);
}

// DIR/scene.json: block.json without its tool, with `dt` and `steps`.
fs::path write_block_without_tools(const fs::path& dir, double dt, int64_t steps) {
  nlohmann::json scene = nlohmann::json::parse(read_text(kData / "block.json"));
  scene["simulation"]["dt"] = dt;
  scene["simulation"]["steps"] = steps;
  scene.erase("tools");
  write_text(dir / "scene.json", scene.dump(2));
  return dir / "scene.json";
}

// Starts phyxel run SCENE --out OUT --quiet in a child process, stderr to ERR.
pid_t start_run(const fs::path& scene, const fs::path& out, const fs::path& err) {
  const pid_t pid = fork();
  if (pid == 0) {
    if (!freopen(err.c_str(), "w", stderr)) _exit(126);
    execl(kPhyxel.c_str(), kPhyxel.c_str(), "run", scene.c_str(), "--out", out.c_str(), "--quiet",
          static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

// Waits (up to 30 s) until `file` holds `text`.
bool wait_for_text(const fs::path& file, const std::string& text) {
  for (int i = 0; i < 600; ++i) {
    if (read_text(file).find(text) != std::string::npos) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

// A step of about 600 000 substeps (a minute or more of wall time): the split is said before
// the run starts and the estimated wall time once the first substeps are timed, and SIGTERM
// stops it in the middle of the first step, which it abandons.
TEST(BadInputs, ALongStepSaysSoAndStopsMidStep) {
  const fs::path dir = case_dir("long_step");
  const fs::path out = dir / "out";
  const fs::path scene_file = write_block_without_tools(dir, 200, 3);
  const pid_t run = start_run(scene_file, out, dir / "err.txt");
  ASSERT_GT(run, 0);
  // The split, then the wall time it will take, measured on the first substeps.
  const bool said = wait_for_text(dir / "err.txt", "s of wall time for 3 steps");
  if (said) std::this_thread::sleep_for(std::chrono::milliseconds(300));
  kill(run, SIGTERM);
  int status = 0;
  ASSERT_EQ(waitpid(run, &status, 0), run);
  const std::string err = read_text(dir / "err.txt");
  EXPECT_TRUE(said) << err;
  EXPECT_LT(err.find("each step is split into"), err.find("s of wall time for 3 steps")) << err;
  ASSERT_TRUE(WIFEXITED(status)) << err;
  EXPECT_EQ(WEXITSTATUS(status), 143) << err;
  const nlohmann::json summary = nlohmann::json::parse(read_text(out / "summary.json"));
  EXPECT_EQ(summary.at("steps_done").get<int>(), 0) << summary.dump();
  EXPECT_TRUE(summary.at("interrupted").get<bool>());
}

// Two runs into one folder: the second is refused, naming the folder and the first's process;
// the first, stopped by SIGTERM, removes its lock file.
TEST(BadInputs, SecondRunIntoAFolderInUseIsRefused) {
  const fs::path dir = case_dir("lock");
  const fs::path out = dir / "out";
  const fs::path scene_file = write_block_without_tools(dir, 1e-4, 100000000);
  const pid_t first = start_run(scene_file, out, dir / "first.txt");
  ASSERT_GT(first, 0);
  // The first run holds the folder once its lock file names it.
  const fs::path lock = out / ".phyxel.lock";
  for (int i = 0; i < 600 && read_text(lock) != std::to_string(first) + "\n"; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_EQ(read_text(lock), std::to_string(first) + "\n");
  const Outcome second = run_phyxel({"run", scene_file.string(), "--out", out.string(), "--quiet"},
                                    0, dir / "second.txt");
  kill(first, SIGTERM);
  int status = 0;
  ASSERT_EQ(waitpid(first, &status, 0), first);
  EXPECT_EQ(second.status, 1) << second.err;
  EXPECT_NE(second.err.find("--out " + out.string()), std::string::npos) << second.err;
  EXPECT_NE(second.err.find("in use by another run (process " + std::to_string(first)),
            std::string::npos)
      << second.err;
  EXPECT_EQ(std::count(second.err.begin(), second.err.end(), '\n'), 1) << second.err;
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 143) << read_text(dir / "first.txt");
  EXPECT_FALSE(fs::exists(lock));
  EXPECT_TRUE(fs::exists(out / "summary.json"));
}

// A checkpoint edited and given a new checksum: a tool's name made invalid UTF-8. The resumed
// run refuses it with a message (not a JSON library error) and writes nothing.
TEST(BadInputs, AnEditedCheckpointWithItsChecksumRecomputedIsRefused) {
  const fs::path dir = case_dir("edited_checkpoint");
  const fs::path out = dir / "out";
  const fs::path scene_file = dir / "scene.json";
  write_text(scene_file, read_text(kData / "block.json"));
  const Outcome first = run_phyxel(
      {"run", scene_file.string(), "--out", out.string(), "--quiet", "--checkpoint-every", "3"}, 0,
      dir / "first.txt");
  ASSERT_EQ(first.status, 0) << first.err;
  std::string bytes = read_text(out / "checkpoint.phx");
  const size_t name = bytes.find("probe");
  ASSERT_NE(name, std::string::npos);
  bytes[name + 1] = '\xff';
  uint64_t length = 0;
  std::memcpy(&length, bytes.data() + 16, sizeof length);
  ASSERT_EQ(length, bytes.size());
  const uint64_t sum = fnv1a64(bytes.data(), length - 8);
  std::memcpy(bytes.data() + length - 8, &sum, sizeof sum);
  write_text(out / "checkpoint.phx", bytes);
  const auto before = snapshot(out);
  const Outcome resumed =
      run_phyxel({"run", scene_file.string(), "--resume", out.string(), "--steps", "9", "--quiet"},
                 0, dir / "resumed.txt");
  EXPECT_EQ(resumed.status, 1) << resumed.err;
  EXPECT_NE(resumed.err.find("corrupt checkpoint: tool 0 is not the scene's 'probe'"),
            std::string::npos)
      << resumed.err;
  EXPECT_EQ(resumed.err.find("json"), std::string::npos) << resumed.err;
  EXPECT_EQ(std::count(resumed.err.begin(), resumed.err.end(), '\n'), 1) << resumed.err;
  EXPECT_EQ(snapshot(out), before) << "the folder changed";
}

}  // namespace
}  // namespace phyxel
