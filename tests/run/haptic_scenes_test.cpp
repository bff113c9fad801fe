// The haptic variants of the surgery scenes (scenes/*_haptic.json, docs/haptics.md) driven by the
// UDP reference driver PHYXEL_BINARY_DIR "/tools/haptic_udp_client", as a user would run them;
// and a second sender on the same port, whose poses the run drops (the first sender is pinned).
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "tests/physics/physics_fixtures.h"
#include "tests/support/support.h"

namespace phyxel {
namespace {

namespace fs = std::filesystem;
const std::string kClient = PHYXEL_BINARY_DIR "/tools/haptic_udp_client";

using phyxel::test::kPhyxel;
using phyxel::test::read_text;

// A UDP port on 127.0.0.1 free a moment ago: bound to port 0, read back, closed.
int free_udp_port() {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof addr;
  int port = 0;
  if (fd >= 0 && ::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0 &&
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len) == 0)
    port = ntohs(addr.sin_port);
  if (fd >= 0) ::close(fd);
  return port;
}

struct Drive {
  std::string scene;  // under scenes/
  int steps;          // a short run (a second or two of wall time on one core)
};

// The driver replays the scene's haptic tool path for 4 s from before phyxel starts; phyxel
// runs `steps` paced steps; `intruder` also sends a line far from the tissue from another
// socket, once the driver is pinned.
struct Driven {
  fs::path dir;
  nlohmann::json summary;
};
Driven drive(const Drive& d, const std::string& name, bool intruder) {
  const fs::path dir = test::test_output_dir("haptic_scene_" + name);
  const std::string scene = std::string(PHYXEL_SOURCE_DIR) + "/scenes/" + d.scene;
  const std::string port = std::to_string(free_udp_port()), s = dir.string();
  std::string command = "( timeout 30 " + kClient + " --port " + port + " --scene " + scene +
                        " --seconds 4 --log " + s + "/forces.csv >" + s +
                        "/client.txt 2>&1; echo $? >" + s + "/client_rc ) & ";
  // The intruder starts once the driver's force log has its first block on disk (some 150
  // forces back: the driver is pinned), not after a fixed delay, which a loaded machine beat.
  if (intruder)
    command += "( timeout 10 sh -c \"while [ ! -s " + s +
               "/forces.csv ]; do sleep 0.01; done\"; timeout 30 " + kClient + " --port " + port +
               " --from 1,1,1 --to 1,1,2 --seconds 2 >" + s + "/intruder.txt 2>&1 ) & ";
  command += "timeout 60 " + kPhyxel + " run " + scene + " --haptic-device udp:" + port +
             " --steps " + std::to_string(d.steps) + " --render none --threads 1 --quiet --out " +
             s + " >" + s + "/stdout.txt 2>" + s + "/stderr.txt; echo $? >" + s +
             "/phyxel_rc; wait";
  const int status = std::system(("sh -c '" + command + "'").c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << d.scene;
  EXPECT_EQ(read_text(dir / "phyxel_rc"), "0\n")
      << d.scene << ": " << read_text(dir / "stderr.txt");
  EXPECT_EQ(read_text(dir / "client_rc"), "0\n")
      << d.scene << ": " << read_text(dir / "client.txt");
  if (!fs::exists(dir / "summary.json")) return {dir, {}};
  return {dir, nlohmann::json::parse(read_text(dir / "summary.json"))};
}

TEST(HapticScenes, TheReferenceDriverDrivesEachSurgeryScene) {
  const Drive drives[] = {{"scalpel_cut_haptic.json", 150},
                          {"grasper_tear_haptic.json", 40},
                          {"probe_indent_haptic.json", 300},
                          {"brain_tumour_removal_haptic.json", 50},
                          {"breast_resection_haptic.json", 50}};
  for (const Drive& d : drives) {
    SCOPED_TRACE(d.scene);
    const nlohmann::json s = drive(d, d.scene, false).summary;
    ASSERT_TRUE(s.contains("haptics")) << s.dump();
    const nlohmann::json& udp = s["haptics"][0]["udp"];
    EXPECT_GT(udp["poses"].get<int>(), 10) << udp.dump();
    EXPECT_EQ(udp["senders_pinned"].get<int>(), 1) << udp.dump();
    EXPECT_EQ(udp["foreign_dropped"].get<int>(), 0) << udp.dump();
    EXPECT_EQ(s["steps_done"].get<int>(), d.steps);
  }
}

// A second driver on the same port while the first drives: its poses (a line a metre away) are
// dropped and counted, and the tool never goes there.
TEST(HapticScenes, ASecondSenderIsIgnored) {
  const Driven run = drive({"probe_indent_haptic.json", 600}, "intruder", true);
  const nlohmann::json& s = run.summary;
  ASSERT_TRUE(s.contains("haptics")) << s.dump();
  const nlohmann::json& udp = s["haptics"][0]["udp"];
  EXPECT_GT(udp["foreign_dropped"].get<int>(), 10) << udp.dump();
  EXPECT_EQ(udp["senders_pinned"].get<int>(), 1) << udp.dump();
  std::ifstream in(run.dir / "tools.csv");
  std::string row;
  std::getline(in, row);
  int rows = 0;
  while (std::getline(in, row)) {
    std::stringstream fields(row);
    std::string f;
    for (int c = 0; c < 4; ++c) std::getline(fields, f, ',');  // step, t, name, px
    EXPECT_LT(std::abs(std::stod(f)), 0.5) << row;
    ++rows;
  }
  EXPECT_EQ(rows, 600);
}

}  // namespace
}  // namespace phyxel
