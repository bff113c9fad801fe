#include "engine/surgery/haptic_session.h"

#include <arpa/inet.h>

#include <charconv>
#include <stdexcept>

namespace phyxel {
namespace {

int parse_port(const std::string& text, const std::string& spec) {
  int port = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), port);
  if (ec != std::errc() || end != text.data() + text.size() || port < 1 || port > 65535)
    throw HapticError("--haptic-device " + spec + ": \"" + text +
                      "\" is not a port; allowed udp:PORT or udp:ADDRESS:PORT, PORT 1-65535");
  return port;
}

}  // namespace

HapticDeviceSpec parse_haptic_device_spec(const std::string& spec) {
  HapticDeviceSpec parsed;
  if (spec == "scripted") return parsed;
  if (spec.rfind("udp:", 0) != 0)
    throw HapticError("--haptic-device " + spec +
                      ": unknown device; allowed scripted (the tool's path), udp:PORT or "
                      "udp:ADDRESS:PORT (an external device driver, docs/haptics.md)");
  const std::string rest = spec.substr(4);
  const size_t colon = rest.rfind(':');
  parsed.udp = true;
  parsed.address = colon == std::string::npos ? "127.0.0.1" : rest.substr(0, colon);
  parsed.port = parse_port(colon == std::string::npos ? rest : rest.substr(colon + 1), spec);
  in_addr addr{};
  if (inet_pton(AF_INET, parsed.address.c_str(), &addr) != 1)
    throw HapticError("--haptic-device " + spec + ": \"" + parsed.address +
                      "\" is not an IPv4 address; allowed udp:PORT or udp:ADDRESS:PORT with a "
                      "dotted quad such as 127.0.0.1 (this machine only) or 0.0.0.0");
  return parsed;
}

std::shared_ptr<HapticDevice> make_haptic_device(const std::string& spec, const ToolDesc& tool,
                                                 int index, const std::string& peer) {
  const HapticDeviceSpec parsed = parse_haptic_device_spec(spec);
  if (!parsed.udp) return std::make_shared<ScriptedDevice>(tool.path);
  if (parsed.port + index > 65535)
    throw HapticError("--haptic-device " + spec + ": haptic tool " + std::to_string(index) +
                      " would listen on port " + std::to_string(parsed.port + index) +
                      "; use a lower port");
  return std::make_shared<UdpDevice>(static_cast<uint16_t>(parsed.port + index), parsed.address,
                                     0.25, peer);
}

HapticSession::HapticSession(const Scene& scene, const std::string& spec, const std::string& peer)
    : loop_of_(scene.tools.size(), -1) {
  int index = 0;
  for (size_t t = 0; t < scene.tools.size(); ++t)
    if (scene.tools[t].control == ToolDesc::Control::Haptic)
      add(scene, t, make_haptic_device(spec, scene.tools[t], index++, peer));
}

HapticSession::HapticSession(
    const Scene& scene, const std::function<std::shared_ptr<HapticDevice>(size_t tool)>& device_of)
    : loop_of_(scene.tools.size(), -1) {
  for (size_t t = 0; t < scene.tools.size(); ++t)
    if (scene.tools[t].control == ToolDesc::Control::Haptic) add(scene, t, device_of(t));
}

HapticSession::~HapticSession() {
  stop();
}

void HapticSession::add(const Scene& scene, size_t tool, std::shared_ptr<HapticDevice> device) {
  const ToolDesc& desc = scene.tools[tool];
  CouplingSettings coupling = desc.coupling;
  coupling.max_speed = live_tool_speed(scene, desc);  // the physics' ToolTrack caps it too
  loop_of_[tool] = static_cast<int>(loops_.size());
  loops_.push_back(
      {tool, desc.name,
       std::make_unique<HapticLoop>(std::move(device), coupling, pose_at(desc.path, 0.0))});
}

void HapticSession::start() {
  for (ToolLoop& l : loops_) l.loop->start();
}

void HapticSession::stop() {
  for (ToolLoop& l : loops_) l.loop->stop();
}

ToolTrack::PoseSource HapticSession::pose_source() const {
  return [this](size_t tool, double) {
    const int k = tool < loop_of_.size() ? loop_of_[tool] : -1;
    if (k < 0)
      throw std::logic_error("HapticSession: tool " + std::to_string(tool) + " is not haptic");
    return loops_[k].loop->tool_pose();
  };
}

void HapticSession::publish(double sim_time, const std::vector<ToolStepRecord>& records) {
  const double now = HapticLoop::clock();
  for (ToolLoop& l : loops_)
    if (l.tool < records.size())
      l.loop->publish({sim_time, now, records[l.tool].hand_force(), records[l.tool].contacts});
}

}  // namespace phyxel
