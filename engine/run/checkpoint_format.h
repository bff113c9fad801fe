// The byte layout shared by checkpoint.cpp (the file, its header and the run's sections 1-8) and
// checkpoint_surgery.cpp (the surgical state's sections 9-15): section tags, the writer and the
// reader. Internal to engine/run; docs/checkpoint.md has the layout.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "engine/run/checkpoint.h"

namespace phyxel::checkpoint_format {

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
  kCuts = 9,           // severed pairs (i, j, t) and the scalpels' cutting statistics
  kCutFeedback = 10,   // the scalpels' largest feedback, friction and depth (ToolRunStats)
  kTorn = 11,          // per severed pair of kCuts, 1 where it was torn (SeveredPair::torn)
  kGrips = 12,         // per tool: the grasper's jaws closed and what they hold
  kAspiration = 13,    // the aspirator: removed phyxels, surface, severed log read, totals
  kCutBand = 14,       // the SCNI band: its quads, counts and cells (CutBandState)
  kBladeSides = 15,    // per tool: the phyxels its blade keeps on one side, and the side
  kSideNormals = 16,   // per kept side of kBladeSides: the plane's normal it was learned on
  kBladeCutting = 17,  // per tool: 1 where its blade is in the cutting state (past its threshold)
};
inline constexpr size_t kHeaderBytes = 8 + 4 + 4 + 8;  // magic, version, sections, file length
inline constexpr size_t kChecksumBytes = 8;

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
    if (n > (size_ - at_) / each) corrupt("a section runs past its end");
  }
  // Refuses the file: "FILE: corrupt checkpoint: WHAT", one line.
  [[noreturn]] void corrupt(const std::string& what) const {
    throw CheckpointError(file_ + ": corrupt checkpoint: " + what);
  }

 private:
  void need(uint64_t n) const {
    if (n > size_ - at_) corrupt("a section runs past its end");
  }
  const char* data_;
  size_t size_;
  size_t at_ = 0;
  std::string file_;
};

// The surgical state, sections kCuts to kBladeCutting in file order: the cuts and the scalpels'
// statistics, tears, grips, the aspirator, the cut band, the blades' kept sides and planes and
// their cutting states.
void write_surgery_sections(Writer& w, const Checkpoint& c);
// Reads section `tag` into `c` when it is one of those; skips any other (not read).
void read_surgery_section(Reader& r, uint32_t tag, Checkpoint& c);

}  // namespace phyxel::checkpoint_format
