#include "engine/run/checkpoint.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "engine/run/checkpoint_format.h"

namespace phyxel {
using namespace checkpoint_format;
namespace {

void write_sections(Writer& w, const Checkpoint& c) {
  w.begin_section(kIdentity);
  w.put<uint64_t>(c.scene_hash);
  w.put<uint64_t>(c.set_hash);
  w.put_string(c.solver);
  w.put_string(c.device);
  w.end_section();

  w.begin_section(kTime);
  w.put<int64_t>(c.step);
  w.put<double>(c.time);
  w.put<double>(c.dt_requested);
  w.put<int64_t>(c.substeps);
  w.put<int64_t>(c.check_every);
  w.put<int64_t>(c.checkpoint_every);
  w.put<int64_t>(c.total);
  w.end_section();

  w.begin_section(kState);
  w.put_vec3s(c.displacement);
  w.put_vec3s(c.velocity);
  w.end_section();

  w.begin_section(kSleep);
  w.put_array(c.awake);
  w.put_array(c.object_below_since);
  w.end_section();

  w.begin_section(kLoads);
  w.put<int64_t>(c.loads_applied);
  w.put<int64_t>(c.load_changes);
  w.end_section();

  w.begin_section(kChecks);
  w.put<int64_t>(c.rest_below_since);
  w.put<int64_t>(c.sleeps);
  w.put<int64_t>(c.wakes);
  w.put_vec3s(c.last_check_u);
  w.end_section();

  w.begin_section(kTools);
  w.put<uint64_t>(c.tool_stats.size());
  for (size_t t = 0; t < c.tool_stats.size(); ++t) {
    const ToolRunStats& s = c.tool_stats[t];
    w.put_string(s.name);
    w.put_vec3(c.tool_poses[t].position);
    w.put_vec3(c.tool_poses[t].axis);
    w.put_vec3(s.last_force);
    w.put<double>(s.max_force);
    w.put<uint32_t>(s.contacts);
    w.put<uint32_t>(s.max_contacts);
    w.put<int64_t>(s.steps_in_contact);
  }
  w.end_section();

  w.begin_section(kTopology);
  w.put_array(c.flags);
  w.end_section();

  write_surgery_sections(w, c);
}

void read_section(Reader& r, uint32_t tag, Checkpoint& c) {
  switch (tag) {
    case kIdentity:
      c.scene_hash = r.get<uint64_t>();
      c.set_hash = r.get<uint64_t>();
      c.solver = r.get_string();
      c.device = r.get_string();
      break;
    case kTime:
      c.step = r.get<int64_t>();
      c.time = r.get<double>();
      c.dt_requested = r.get<double>();
      c.substeps = r.get<int64_t>();
      c.check_every = r.get<int64_t>();
      c.checkpoint_every = r.get<int64_t>();
      c.total = r.get<int64_t>();
      break;
    case kState:
      c.displacement = r.get_vec3s();
      c.velocity = r.get_vec3s();
      break;
    case kSleep:
      c.awake = r.get_array<uint8_t>();
      c.object_below_since = r.get_array<int64_t>();
      break;
    case kLoads:
      c.loads_applied = r.get<int64_t>();
      c.load_changes = r.get<int64_t>();
      break;
    case kChecks:
      c.rest_below_since = r.get<int64_t>();
      c.sleeps = r.get<int64_t>();
      c.wakes = r.get<int64_t>();
      c.last_check_u = r.get_vec3s();
      break;
    case kTools: {
      const uint64_t n = r.get<uint64_t>();
      for (uint64_t t = 0; t < n; ++t) {
        ToolRunStats s;
        s.name = r.get_string();
        ToolPose pose;
        pose.position = r.get_vec3();
        pose.axis = r.get_vec3();
        s.last_force = r.get_vec3();
        s.max_force = r.get<double>();
        s.contacts = r.get<uint32_t>();
        s.max_contacts = r.get<uint32_t>();
        s.steps_in_contact = r.get<int64_t>();
        c.tool_poses.push_back(pose);
        c.tool_stats.push_back(s);
      }
      break;
    }
    case kTopology:
      c.flags = r.get_array<uint32_t>();
      break;
    default:  // the surgical state's sections, and any this version does not know (skipped)
      read_surgery_section(r, tag, c);
      break;
  }
}

std::string hex(uint64_t h) {
  char text[32];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
  return text;
}

}  // namespace

uint64_t fnv1a64(const void* data, size_t size, uint64_t h) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) {
    h ^= p[i];
    h *= 0x100000001b3ull;
  }
  return h;
}

uint64_t file_hash(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw CheckpointError(file.string() + ": cannot read the scene file to identify it");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string bytes = ss.str();
  return fnv1a64(bytes.data(), bytes.size());
}

uint64_t phyxel_set_hash(const PhyxelSet& set) {
  const uint64_t n = set.size();
  uint64_t h = fnv1a64(&n, sizeof n);
  for (const Vec3& x : set.rest)
    for (int k = 0; k < 3; ++k) {
      const double v = x[k];
      h = fnv1a64(&v, sizeof v, h);
    }
  return h;
}

std::string solver_identity(const std::string& device) {
  if (device.rfind("cpu (", 0) == 0) {
    const size_t comma = device.find(',');
    if (comma != std::string::npos) return device.substr(0, comma) + ")";
  }
  return device;
}

void write_checkpoint(const std::filesystem::path& file, const Checkpoint& checkpoint) {
  if (checkpoint.tool_poses.size() != checkpoint.tool_stats.size())
    throw CheckpointError(file.string() + ": tool poses and statistics differ in count");
  Writer w;
  // Reserved up front: without it GCC 12 at -O3, inlining write_sections here, takes the
  // vector's growth for a write past its end (-Wstringop-overflow, a false positive).
  w.bytes().reserve(size_t{1} << 16);
  w.bytes().insert(w.bytes().end(), kCheckpointMagic, kCheckpointMagic + 8);
  w.put<uint32_t>(kCheckpointVersion);
  w.put<uint32_t>(0);  // section count, patched below
  w.put<uint64_t>(0);  // file length, patched below
  write_sections(w, checkpoint);
  std::vector<char>& bytes = w.bytes();
  const uint32_t sections = w.sections();
  const uint64_t length = bytes.size() + kChecksumBytes;
  std::memcpy(bytes.data() + 12, &sections, sizeof sections);
  std::memcpy(bytes.data() + 16, &length, sizeof length);
  const uint64_t sum = fnv1a64(bytes.data(), bytes.size());
  w.put<uint64_t>(sum);

  const std::filesystem::path tmp = file.string() + ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0)
    throw CheckpointError(file.string() + ": cannot write the checkpoint (" + std::strerror(errno) +
                          ")");
  const char* p = bytes.data();
  size_t left = bytes.size();
  bool ok = true;
  while (ok && left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      ok = false;
      break;
    }
    p += n;
    left -= static_cast<size_t>(n);
  }
  const int saved = errno;
  ok = ok && ::fsync(fd) == 0;
  const int sync_errno = errno;
  ok = (::close(fd) == 0) && ok;
  if (ok && std::rename(tmp.c_str(), file.c_str()) == 0) return;
  const std::string why = std::strerror(left > 0 ? saved : sync_errno != 0 ? sync_errno : errno);
  std::error_code ec;
  std::filesystem::remove(tmp, ec);
  throw CheckpointError(file.string() + ": cannot write the checkpoint (" + why + ")");
}

Checkpoint read_checkpoint(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::error_code ec;
  if (!std::filesystem::exists(file, ec))
    throw CheckpointError(name +
                          ": no checkpoint there (missing file; was the run started with "
                          "--checkpoint-every?)");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw CheckpointError(name + ": cannot read the checkpoint");
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_checkpoint(ss.str(), name);
}

Checkpoint parse_checkpoint(const std::string& bytes, const std::string& name) {
  if (bytes.size() >= 8 && std::memcmp(bytes.data(), kCheckpointMagic, 7) != 0)
    throw CheckpointError(name + ": not a phyxel checkpoint (bad magic number)");
  if (bytes.size() < kHeaderBytes + kChecksumBytes)
    throw CheckpointError(name + ": truncated checkpoint (" + std::to_string(bytes.size()) +
                          " bytes, shorter than its header)");
  uint32_t version = 0;
  std::memcpy(&version, bytes.data() + 8, sizeof version);
  if (version != kCheckpointVersion || bytes[7] != kCheckpointMagic[7])
    throw CheckpointError(name + ": checkpoint format version " + std::to_string(version) +
                          ", this phyxel reads version " + std::to_string(kCheckpointVersion));
  uint32_t sections = 0;
  uint64_t length = 0;
  std::memcpy(&sections, bytes.data() + 12, sizeof sections);
  std::memcpy(&length, bytes.data() + 16, sizeof length);
  if (bytes.size() < length)
    throw CheckpointError(name + ": truncated checkpoint (" + std::to_string(bytes.size()) +
                          " of " + std::to_string(length) + " bytes)");
  if (bytes.size() > length)
    throw CheckpointError(name + ": corrupt checkpoint (" + std::to_string(bytes.size()) +
                          " bytes, its header says " + std::to_string(length) + ")");
  uint64_t stored = 0;
  std::memcpy(&stored, bytes.data() + length - kChecksumBytes, sizeof stored);
  const uint64_t sum = fnv1a64(bytes.data(), length - kChecksumBytes);
  if (sum != stored)
    throw CheckpointError(name + ": checksum mismatch (stored " + hex(stored) + ", computed " +
                          hex(sum) + "): the checkpoint is corrupt");
  Checkpoint c;
  Reader r(bytes.data(), length - kChecksumBytes, name);
  r.seek(kHeaderBytes);
  bool side_normals = false;
  for (uint32_t s = 0; s < sections; ++s) {
    const uint32_t tag = r.get<uint32_t>();
    const uint64_t size = r.get<uint64_t>();
    side_normals = side_normals || tag == kSideNormals;
    const size_t start = r.at();
    if (size > length - kChecksumBytes - start)
      throw CheckpointError(name + ": corrupt checkpoint: section " + std::to_string(tag) +
                            " runs past the end");
    read_section(r, tag, c);
    if (tag <= kTopology && r.at() != start + size)
      throw CheckpointError(name + ": corrupt checkpoint: section " + std::to_string(tag) +
                            " has the wrong length");
    r.seek(start + size);
  }
  // Sides without the planes they were learned on (written before section 16): none kept, as
  // before section 15; the blade learns them again (docs/decisions.md).
  if (!side_normals) c.blade_sides.clear();
  const size_t n = c.displacement.size();
  if (c.velocity.size() != n || c.flags.size() != n ||
      c.awake.size() != c.object_below_since.size())
    throw CheckpointError(name + ": corrupt checkpoint: its sections disagree on the counts");
  return c;
}

void check_checkpoint_matches(const Checkpoint& c, const std::filesystem::path& file,
                              uint64_t scene_hash, const PhyxelSet& set,
                              const std::string& device) {
  const std::string name = file.string();
  if (c.scene_hash != scene_hash)
    throw CheckpointError(name + ": written for another scene file (scene hash " +
                          hex(c.scene_hash) + ", this scene's is " + hex(scene_hash) + ")");
  if (c.set_hash != phyxel_set_hash(set) || c.displacement.size() != set.size())
    throw CheckpointError(name + ": written for another phyxel set (" +
                          std::to_string(c.displacement.size()) + " phyxels, this scene samples " +
                          std::to_string(set.size()) + ")");
  if (c.awake.size() != set.objects.size())
    throw CheckpointError(name + ": written for another set of objects");
  for (size_t i = 0; i < set.size(); ++i)
    if ((c.flags[i] & kRemoved) != (set.flags[i] & kRemoved))
      throw CheckpointError(name + ": its topology (removed phyxels) differs from the scene's");
  const std::string identity = solver_identity(device);
  if (c.solver != identity)
    throw CheckpointError(name + ": written by " + c.solver + ", this run uses " + identity +
                          "; resume on the same device and precision (results would not be "
                          "bit-identical otherwise)");
}

}  // namespace phyxel
