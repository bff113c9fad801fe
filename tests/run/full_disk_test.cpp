// Writers of a run on a full disk: every output (points .vtp, summary.json through
// write_file_atomically, frame PNGs, tools.csv) is written to FILE.tmp and renamed; a failed
// write removes FILE.tmp and says the disk is full (or which write failed), naming the file.
// A full disk is simulated in two ways: FILE.tmp is a link to /dev/full (every write fails
// with ENOSPC), and the phyxel binary runs under a file size limit (RLIMIT_FSIZE via
// `ulimit -f`, with SIGXFSZ ignored, so that writes past it fail with EFBIG).
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>

#include "engine/run/atomic_file.h"
#include "engine/run/tool_trace.h"
#include "engine/run/vtp_writer.h"
#include "render/image.h"
#include "tests/physics/physics_fixtures.h"
#include "tests/support/support.h"

namespace phyxel {
namespace {

namespace fs = std::filesystem;

using phyxel::test::read_text;

std::vector<std::string> temp_files(const fs::path& dir) {
  std::vector<std::string> out;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().extension() == ".tmp") out.push_back(entry.path().filename().string());
  return out;
}

bool dev_full_available() {
  std::ofstream full("/dev/full");
  return full.good();
}

// Makes DIR/NAME.tmp a link to /dev/full, runs `write`, and checks its error and that no
// temporary file (nor the link) is left; FILE keeps its earlier content.
void expect_full_disk_error(const std::string& test, const std::string& name,
                            const std::function<void(const fs::path&)>& write) {
  const fs::path dir = test::test_output_dir("full_disk_" + test);
  const fs::path file = dir / name;
  std::ofstream(file) << "earlier";
  fs::create_symlink("/dev/full", dir / (name + ".tmp"));
  try {
    write(file);
    ADD_FAILURE() << name << ": no error on a full disk";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(file.string()), std::string::npos) << msg;
    EXPECT_NE(msg.find("the disk is full"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
  EXPECT_TRUE(temp_files(dir).empty()) << name;
  EXPECT_FALSE(fs::is_symlink(dir / (name + ".tmp")));
  EXPECT_EQ(read_text(file), "earlier");
}

TEST(FullDisk, EveryWriterRemovesItsTemporaryFileAndSaysTheDiskIsFull) {
  if (!dev_full_available()) GTEST_SKIP() << "no /dev/full";
  const PhyxelSet set = sample_scene(
      test::box_scene(Vec3(0, 0, 0), Vec3(0.005, 0.0025, 0.0025), 0.0025, test::tissue()));
  PointState state;
  state.displacement.assign(set.size(), Vec3::Zero());
  state.velocity.assign(set.size(), Vec3::Zero());
  state.von_mises.assign(set.size(), 0.0);
  expect_full_disk_error("vtp", "points_000010.vtp",
                         [&](const fs::path& file) { write_points_vtp(file, set, state, true); });
  expect_full_disk_error("summary", "summary.json", [](const fs::path& file) {
    write_file_atomically(file, "{\"steps_done\": 10}\n");
  });
  expect_full_disk_error("png", "frame_000010.png", [](const fs::path& file) {
    render::RgbaImage image;
    image.width = image.height = 64;
    image.pixels.assign(64 * 64 * 4, 200);
    render::write_png(file, image);
  });
  expect_full_disk_error("tools", "tools.csv", [](const fs::path& file) {
    ToolDesc tool;
    tool.name = "probe";
    ToolTraceWriter trace(file, {tool});
    // Rows go out in 64 KiB blocks: enough rows that the write happens before close().
    for (int64_t step = 0; step < 2000; ++step) trace.write(step, 1e-4 * step, {ToolStepRecord{}});
    trace.close();
  });
}

TEST(FullDisk, LargeWritesFailToo) {
  if (!dev_full_available()) GTEST_SKIP() << "no /dev/full";
  expect_full_disk_error("large", "big.bin", [](const fs::path& file) {
    write_file_atomically(file, std::string(1 << 20, 'x'));
  });
}

TEST(FullDisk, ToolTraceIsWholeAfterCloseAndKeptWhenTheRunStopsEarly) {
  const fs::path dir = test::test_output_dir("full_disk_trace_ok");
  ToolDesc tool;
  tool.name = "probe";
  {
    ToolTraceWriter trace(dir / "tools.csv", {tool});
    trace.write(0, 0, {ToolStepRecord{}});
    EXPECT_TRUE(fs::exists(dir / "tools.csv.tmp"));
    trace.close();
  }
  EXPECT_EQ(std::count(std::istreambuf_iterator<char>(std::ifstream(dir / "tools.csv").rdbuf()),
                       std::istreambuf_iterator<char>(), '\n'),
            2);
  {
    ToolTraceWriter trace(dir / "tools.csv", {tool});
    for (int64_t step = 0; step < 3; ++step) trace.write(step, 0, {ToolStepRecord{}});
  }  // destroyed without close(): a run stopped by an error keeps the rows it wrote
  EXPECT_TRUE(temp_files(dir).empty());
  EXPECT_EQ(std::count(std::istreambuf_iterator<char>(std::ifstream(dir / "tools.csv").rdbuf()),
                       std::istreambuf_iterator<char>(), '\n'),
            4);
}

// `phyxel run` under a file size limit smaller than one points file: it stops with one line
// naming the file and the cause, exit status 1, and leaves no *.tmp in the output folder. The
// shell does not ignore SIGXFSZ: phyxel ignores it itself (else it is killed, status 153).
TEST(FullDisk, RunStoppedByTheFileSizeLimitLeavesNoTemporaryFile) {
  const fs::path dir = test::test_output_dir("full_disk_cli");
  std::string scene = read_text(fs::path(PHYXEL_SOURCE_DIR) / "scenes/beam.json");
  const size_t at = scene.find("\"every\": 0");
  ASSERT_NE(at, std::string::npos);
  scene.replace(at, 10, "\"every\": 2");
  std::ofstream(dir / "beam.json") << scene;
  const fs::path err = dir / "stderr.txt";
  // 64 blocks of 1 KiB: the beam's points file is far larger; summary.json would fit.
  const std::string cmd = "bash -c \"ulimit -f 64; exec " + std::string(PHYXEL_BINARY_DIR) +
                          "/app/phyxel run " + (dir / "beam.json").string() +
                          " --steps 4 --threads 1 --quiet --out " + dir.string() + "\" 2>" +
                          err.string();
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status)) << status;
  EXPECT_EQ(WEXITSTATUS(status), 1);
  std::string msg = read_text(err);
  // The beam's dt is split into substeps, which the run says before it starts.
  const std::string notice = "phyxel run: requested dt ";
  ASSERT_EQ(msg.rfind(notice, 0), 0u) << msg;
  msg = msg.substr(msg.find('\n') + 1);
  EXPECT_EQ(std::count(msg.begin(), msg.end(), '\n'), 1) << msg;
  // The first points file is due at step 2.
  EXPECT_NE(msg.find((dir / "points_000002.vtp").string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("file size limit"), std::string::npos) << msg;
  EXPECT_TRUE(temp_files(dir).empty());
  EXPECT_FALSE(fs::exists(dir / "points_000002.vtp"));
  EXPECT_FALSE(fs::exists(dir / "summary.json"));
}

}  // namespace
}  // namespace phyxel
