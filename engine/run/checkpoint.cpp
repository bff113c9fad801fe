#include "engine/run/checkpoint.h"

#include <fcntl.h>
#include <unistd.h>

#include <array>
#include <bit>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

namespace phyxel {
namespace {

static_assert(std::endian::native == std::endian::little,
              "checkpoint.phx is little-endian; this writer stores native words");

// Section tags, in file order.
enum Section : uint32_t {
  kIdentity = 1,
  kTime = 2,
  kState = 3,
  kSleep = 4,
  kLoads = 5,
  kChecks = 6,
  kTools = 7,
  kTopology = 8,
  kCuts = 9,          // severed pairs (i, j, t) and the scalpels' cutting statistics
  kCutFeedback = 10,  // the scalpels' largest feedback, friction and depth (ToolRunStats)
  kTorn = 11,         // per severed pair of kCuts, 1 where it was torn (SeveredPair::torn)
  kGrips = 12,        // per tool: the grasper's jaws closed and what they hold
  kAspiration = 13,   // the aspirator: removed phyxels, surface, severed log read, totals
  kCutBand = 14,      // the SCNI band: its quads, counts and cells (CutBandState)
  kBladeSides = 15,   // per tool: the phyxels its blade keeps on one side, and the side
};
constexpr size_t kHeaderBytes = 8 + 4 + 4 + 8;  // magic, version, sections, file length
constexpr size_t kChecksumBytes = 8;

class Writer {
 public:
  template <class T>
  void put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const char*>(&value);
    bytes_.insert(bytes_.end(), p, p + sizeof(T));
  }
  void put_string(const std::string& s) {
    put<uint32_t>(static_cast<uint32_t>(s.size()));
    bytes_.insert(bytes_.end(), s.begin(), s.end());
  }
  void put_vec3(const Vec3& v) {
    for (int k = 0; k < 3; ++k) put<double>(v[k]);
  }
  void put_vec3s(const std::vector<Vec3>& v) {
    put<uint64_t>(v.size());
    for (const Vec3& x : v) put_vec3(x);
  }
  template <class T>
  void put_array(const std::vector<T>& v) {
    put<uint64_t>(v.size());
    for (const T& x : v) put<T>(x);
  }
  // Sections: tag, payload length (patched by end_section), payload.
  void begin_section(uint32_t tag) {
    put<uint32_t>(tag);
    length_at_ = bytes_.size();
    put<uint64_t>(0);
    ++sections_;
  }
  void end_section() {
    const uint64_t length = bytes_.size() - length_at_ - sizeof(uint64_t);
    std::memcpy(bytes_.data() + length_at_, &length, sizeof length);
  }
  std::vector<char>& bytes() { return bytes_; }
  uint32_t sections() const { return sections_; }

 private:
  std::vector<char> bytes_;
  size_t length_at_ = 0;
  uint32_t sections_ = 0;
};

class Reader {
 public:
  Reader(const char* data, size_t size, const std::string& file)
      : data_(data), size_(size), file_(file) {}
  template <class T>
  T get() {
    need(sizeof(T));
    T value;
    std::memcpy(&value, data_ + at_, sizeof(T));
    at_ += sizeof(T);
    return value;
  }
  std::string get_string() {
    const uint32_t n = get<uint32_t>();
    need(n);
    std::string s(data_ + at_, n);
    at_ += n;
    return s;
  }
  Vec3 get_vec3() {
    Vec3 v;
    for (int k = 0; k < 3; ++k) v[k] = get<double>();
    return v;
  }
  std::vector<Vec3> get_vec3s() {
    const uint64_t n = get<uint64_t>();
    need_items(n, 3 * sizeof(double));
    std::vector<Vec3> v(n);
    for (Vec3& x : v) x = get_vec3();
    return v;
  }
  template <class T>
  std::vector<T> get_array() {
    const uint64_t n = get<uint64_t>();
    need_items(n, sizeof(T));
    std::vector<T> v(n);
    for (T& x : v) x = get<T>();
    return v;
  }
  size_t at() const { return at_; }
  void seek(size_t at) { at_ = at; }
  // n items of `each` bytes (a count read from the file: n * each may overflow).
  void need_items(uint64_t n, uint64_t each) const {
    if (n > (size_ - at_) / each)
      throw CheckpointError(file_ + ": corrupt checkpoint: a section runs past its end");
  }

 private:
  void need(uint64_t n) const {
    if (n > size_ - at_)
      throw CheckpointError(file_ + ": corrupt checkpoint: a section runs past its end");
  }
  const char* data_;
  size_t size_;
  size_t at_ = 0;
  std::string file_;
};

// The aspirator's removals and the cut band's quads.
void write_surgery_sections(Writer& w, const Checkpoint& c) {
  const AspiratorState& a = c.aspiration;
  w.begin_section(kAspiration);
  w.put<uint64_t>(a.log_cursor);
  w.put_array(a.removed);
  w.put_array(a.surface);
  w.put<int64_t>(a.events);
  w.put<double>(a.max_radius);
  w.put_array(a.removed_mass);
  w.put_array(a.removed_volume);
  w.end_section();

  const CutBandState& band = c.band;
  w.begin_section(kCutBand);
  w.put<uint64_t>(band.quads.size());
  for (const auto& q : band.quads)
    for (const Vec3& x : q) w.put_vec3(x);
  w.put<uint64_t>(band.quads_built);
  w.put<uint64_t>(band.quads_before_chunk);
  w.put_array(band.phyxel);
  w.put_array(band.dirty);
  w.put_array(band.built_with);
  w.end_section();

  w.begin_section(kBladeSides);
  w.put<uint64_t>(c.blade_sides.size());
  for (const std::vector<BladeSide>& tool : c.blade_sides) {
    w.put<uint64_t>(tool.size());
    for (const BladeSide& b : tool) {
      w.put<uint32_t>(b.phyxel);
      w.put<uint8_t>(uint8_t(b.side));
    }
  }
  w.end_section();
}

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

  w.begin_section(kCuts);
  w.put<uint64_t>(c.severed.size());
  for (const SeveredPair& p : c.severed) {
    w.put<uint32_t>(p.i);
    w.put<uint32_t>(p.j);
    w.put<float>(p.t);
  }
  w.put<uint64_t>(c.tool_stats.size());
  for (const ToolRunStats& s : c.tool_stats) {
    w.put<double>(s.max_cut_force);
    w.put<int64_t>(s.cutting_substeps);
  }
  w.end_section();

  w.begin_section(kCutFeedback);
  w.put<uint64_t>(c.tool_stats.size());
  for (const ToolRunStats& s : c.tool_stats) {
    w.put<double>(s.max_feedback);
    w.put<double>(s.max_friction);
    w.put<double>(s.max_depth);
  }
  w.end_section();

  w.begin_section(kTorn);
  std::vector<uint8_t> torn(c.severed.size());
  for (size_t k = 0; k < torn.size(); ++k) torn[k] = c.severed[k].torn;
  w.put_array(torn);
  w.end_section();

  w.begin_section(kGrips);
  w.put<uint64_t>(c.grips.size());
  for (const Grip& g : c.grips) {
    w.put<uint8_t>(g.closed ? 1 : 0);
    w.put<uint64_t>(g.held.size());
    for (const GripEntry& e : g.held) {
      w.put<uint32_t>(e.phyxel);
      w.put_vec3(e.offset);
    }
  }
  w.end_section();

  write_surgery_sections(w, c);
}

void read_cut_band(Reader& r, CutBandState& band) {
  const uint64_t n = r.get<uint64_t>();
  for (uint64_t k = 0; k < n; ++k) {
    std::array<Vec3, 4> q;
    for (Vec3& x : q) x = r.get_vec3();
    band.quads.push_back(q);
  }
  band.quads_built = r.get<uint64_t>();
  band.quads_before_chunk = r.get<uint64_t>();
  band.phyxel = r.get_array<uint32_t>();
  band.dirty = r.get_array<uint8_t>();
  band.built_with = r.get_array<uint64_t>();
}

void read_blade_sides(Reader& r, Checkpoint& c) {
  const uint64_t tools = r.get<uint64_t>();
  for (uint64_t t = 0; t < tools; ++t) {
    const uint64_t n = r.get<uint64_t>();
    r.need_items(n, sizeof(uint32_t) + sizeof(uint8_t));  // a corrupt count: refused, not allocated
    std::vector<BladeSide> kept(n);
    for (BladeSide& b : kept) {
      b.phyxel = r.get<uint32_t>();
      b.side = r.get<uint8_t>();
      if (b.side != kSidePlus && b.side != kSideMinus)
        throw CheckpointError("corrupt checkpoint: blade side " + std::to_string(b.side) +
                              " for phyxel " + std::to_string(b.phyxel));
    }
    c.blade_sides.push_back(std::move(kept));
  }
}

void read_grips(Reader& r, Checkpoint& c) {
  const uint64_t tools = r.get<uint64_t>();
  for (uint64_t t = 0; t < tools; ++t) {
    Grip g;
    g.closed = r.get<uint8_t>() != 0;
    const uint64_t n = r.get<uint64_t>();
    for (uint64_t k = 0; k < n; ++k) {
      GripEntry e;
      e.phyxel = r.get<uint32_t>();
      e.offset = r.get_vec3();
      g.held.push_back(e);
    }
    c.grips.push_back(std::move(g));
  }
}

void read_aspiration(Reader& r, AspiratorState& a) {
  a.log_cursor = r.get<uint64_t>();
  a.removed = r.get_array<uint32_t>();
  a.surface = r.get_array<uint8_t>();
  a.events = r.get<int64_t>();
  a.max_radius = r.get<double>();
  a.removed_mass = r.get_array<double>();
  a.removed_volume = r.get_array<double>();
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
    case kCuts: {  // after kTools (written in that order)
      const uint64_t n = r.get<uint64_t>();
      for (uint64_t k = 0; k < n; ++k) {
        SeveredPair p;
        p.i = r.get<uint32_t>();
        p.j = r.get<uint32_t>();
        p.t = r.get<float>();
        c.severed.push_back(p);
      }
      const uint64_t tools = r.get<uint64_t>();
      for (uint64_t t = 0; t < tools; ++t) {
        const double max_cut = r.get<double>();
        const int64_t cutting = r.get<int64_t>();
        if (t < c.tool_stats.size()) {
          c.tool_stats[t].max_cut_force = max_cut;
          c.tool_stats[t].cutting_substeps = cutting;
        }
      }
      break;
    }
    case kCutFeedback: {  // after kTools
      const uint64_t tools = r.get<uint64_t>();
      for (uint64_t t = 0; t < tools; ++t) {
        const double feedback = r.get<double>(), friction = r.get<double>(),
                     depth = r.get<double>();
        if (t < c.tool_stats.size()) {
          c.tool_stats[t].max_feedback = feedback;
          c.tool_stats[t].max_friction = friction;
          c.tool_stats[t].max_depth = depth;
        }
      }
      break;
    }
    case kTorn: {  // after kCuts
      const std::vector<uint8_t> torn = r.get_array<uint8_t>();
      if (torn.size() != c.severed.size())
        throw CheckpointError("corrupt checkpoint: " + std::to_string(torn.size()) +
                              " torn flags for " + std::to_string(c.severed.size()) +
                              " severed pairs");
      for (size_t k = 0; k < torn.size(); ++k) c.severed[k].torn = torn[k] != 0;
      break;
    }
    case kGrips:
      read_grips(r, c);
      break;
    case kAspiration:
      read_aspiration(r, c.aspiration);
      break;
    case kCutBand:
      read_cut_band(r, c.band);
      break;
    case kBladeSides:
      read_blade_sides(r, c);
      break;
    default:  // a section this version does not know: skipped
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
  for (uint32_t s = 0; s < sections; ++s) {
    const uint32_t tag = r.get<uint32_t>();
    const uint64_t size = r.get<uint64_t>();
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
