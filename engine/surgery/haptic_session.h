// The haptic side of a run: one HapticLoop (1 kHz thread, virtual coupling) per scene tool with
// "control": "haptic", each on a device, feeding the run loop the simulated tools' poses
// (RunOptions::tool_pose) and taking the tissue's force on them after every step
// (RunOptions::on_tool_step).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "engine/scene/scene.h"
#include "engine/surgery/haptic_device.h"
#include "engine/surgery/haptic_loop.h"
#include "engine/surgery/tool_track.h"

namespace phyxel {

// A --haptic-device spec checked: "scripted", or "udp:PORT" / "udp:ADDRESS:PORT" with PORT
// 1-65535 and ADDRESS an IPv4 dotted quad (default 127.0.0.1). Throws HapticError naming the
// spec and what is allowed.
struct HapticDeviceSpec {
  bool udp = false;
  std::string address;
  int port = 0;
};
HapticDeviceSpec parse_haptic_device_spec(const std::string& spec);

// A device from its command-line spec: "scripted" (the tool's own path, replayed on the wall
// clock), "udp:PORT" or "udp:ADDRESS:PORT" (an external driver, docs/haptics.md). Throws
// HapticError naming the spec and what is allowed.
// `peer`: the one non-loopback sender a udp device accepts (UdpDevice), empty for loopback only.
std::shared_ptr<HapticDevice> make_haptic_device(const std::string& spec, const ToolDesc& tool,
                                                 int index, const std::string& peer = "");

class HapticSession {
 public:
  // Devices from `spec` (make_haptic_device; with udp and several haptic tools, the n-th
  // haptic tool listens on PORT + n). No haptic tool: an empty session.
  HapticSession(const Scene& scene, const std::string& spec, const std::string& peer = "");
  // A device per haptic tool from `device_of(tool)` (the viewer's mouse).
  HapticSession(const Scene& scene,
                const std::function<std::shared_ptr<HapticDevice>(size_t tool)>& device_of);
  ~HapticSession();

  bool empty() const { return loops_.empty(); }
  void start();
  void stop();
  // For RunOptions::tool_pose: the simulated pose of scene tool `tool` now.
  ToolTrack::PoseSource pose_source() const;
  // For RunOptions::on_tool_step: publishes each haptic tool's force to its loop.
  void publish(double sim_time, const std::vector<ToolStepRecord>& records);

  struct ToolLoop {
    size_t tool;  // index into scene.tools
    std::string name;
    std::unique_ptr<HapticLoop> loop;
  };
  const std::vector<ToolLoop>& loops() const { return loops_; }

 private:
  void add(const Scene& scene, size_t tool, std::shared_ptr<HapticDevice> device);
  std::vector<ToolLoop> loops_;
  std::vector<int> loop_of_;  // per scene tool: index into loops_, or -1
};

}  // namespace phyxel
