// The surgical sections of checkpoint.phx (engine/run/checkpoint_surgery.cpp,
// docs/checkpoint.md): what each holds is checked, with one line naming the file, and a file
// with kept sides but without the planes they were learned on resumes with none kept.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "engine/run/checkpoint.h"
#include "engine/run/checkpoint_format.h"
#include "engine/solver/cutting.h"
#include "tests/physics/physics_fixtures.h"
#include "tests/run/checkpoint_fixtures.h"
#include "tests/support/support.h"

namespace phyxel {
namespace {

namespace fs = std::filesystem;

using checkpoint_test::gpu_device_args;
using checkpoint_test::kScalpel;
using checkpoint_test::Ran;
using checkpoint_test::run;
using checkpoint_test::write_bytes;
using checkpoint_test::write_scene;
using test::read_text;

// The sections of checkpoint bytes (docs/checkpoint.md: a 24-byte header, then per section a
// u32 tag, a u64 length and the payload), in file order.
struct SectionSpan {
  uint32_t tag;
  size_t at;  // where its tag is; the payload begins 12 bytes on
  uint64_t length;
};
std::vector<SectionSpan> sections_of(const std::string& bytes) {
  uint32_t sections = 0;
  std::memcpy(&sections, bytes.data() + 12, sizeof sections);
  std::vector<SectionSpan> spans;
  size_t at = checkpoint_format::kHeaderBytes;
  for (uint32_t s = 0; s < sections; ++s) {
    SectionSpan span{0, at, 0};
    std::memcpy(&span.tag, bytes.data() + at, sizeof span.tag);
    std::memcpy(&span.length, bytes.data() + at + 4, sizeof span.length);
    spans.push_back(span);
    at += 12 + span.length;
  }
  return spans;
}

// The payload offset of section `tag` in checkpoint bytes.
size_t section_at(const std::string& bytes, uint32_t tag) {
  for (const SectionSpan& s : sections_of(bytes))
    if (s.tag == tag) return s.at + 12;
  ADD_FAILURE() << "no section " << tag;
  return 0;
}

// The surgical sections' checks of what they hold: a bad blade side, a torn-flag count that
// is not the severed pairs', side normals for other tools than the sides'. Each refusal is one line
// naming the file and what is wrong.
TEST(Checkpoint, CorruptSurgerySectionsNameTheFile) {
  const fs::path dir = test::test_output_dir("checkpoint_surgery_refused");
  Checkpoint c;
  c.solver = c.device = "cpu (double)";
  c.displacement = c.velocity = {Vec3::Zero(), Vec3::Zero()};
  c.flags = {0, 0};
  c.severed = {{0, 1, 0.25f, false}, {0, 1, 0.5f, true}};
  c.blade_sides = {{{1, kSideMinus}}};
  c.blades_cutting = {1};
  const fs::path file = dir / kCheckpointFile;
  write_checkpoint(file, c);
  const std::string bytes = read_text(file);
  const auto refusal = [&](size_t at, char value) {
    std::string b = bytes;
    b[at] = value;
    const uint64_t sum = fnv1a64(b.data(), b.size() - 8);
    std::memcpy(b.data() + b.size() - 8, &sum, sizeof sum);
    write_bytes(file, b);
    try {
      read_checkpoint(file);
    } catch (const CheckpointError& e) {
      return std::string(e.what());
    }
    return std::string("(read without an error)");
  };
  // The first kept side: after the tool count, the tool's count and the phyxel.
  const std::string side = refusal(section_at(bytes, checkpoint_format::kBladeSides) + 20, 7);
  EXPECT_EQ(side.rfind(file.string() + ": corrupt checkpoint: blade side 7 for phyxel 1", 0), 0u)
      << side;
  // The torn flags' count (its low byte), one short of the two severed pairs.
  const std::string torn = refusal(section_at(bytes, checkpoint_format::kTorn), 1);
  EXPECT_EQ(torn.rfind(file.string() + ": corrupt checkpoint: 1 torn flags for 2 severed", 0), 0u)
      << torn;
  // The side normals' tool count (its low byte): two tools where the sides have one.
  const std::string normals = refusal(section_at(bytes, checkpoint_format::kSideNormals), 2);
  EXPECT_EQ(normals.rfind(
                file.string() + ": corrupt checkpoint: side normals for 2 tools, sides for 1", 0),
            0u)
      << normals;
  // The first blade's cutting state, after the array's count.
  const std::string state = refusal(section_at(bytes, checkpoint_format::kBladeCutting) + 8, 7);
  EXPECT_EQ(state.rfind(file.string() + ": corrupt checkpoint: cutting state 7 for tool 0", 0), 0u)
      << state;
  for (const std::string& m : {side, torn, normals, state})
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  write_bytes(file, bytes);
  EXPECT_EQ(read_checkpoint(file).blade_sides.at(0).at(0).side, kSideMinus);
  EXPECT_EQ(read_checkpoint(file).blades_cutting, std::vector<uint8_t>{1});
}

// Checkpoint bytes without the sections `tags` (header count, length and checksum made right).
std::string without_sections(const std::string& bytes, const std::vector<uint32_t>& tags) {
  uint32_t kept = 0;
  std::string out = bytes.substr(0, checkpoint_format::kHeaderBytes);
  for (const SectionSpan& s : sections_of(bytes))
    if (std::find(tags.begin(), tags.end(), s.tag) == tags.end()) {
      out += bytes.substr(s.at, 12 + s.length);
      ++kept;
    }
  out += std::string(checkpoint_format::kChecksumBytes, '\0');
  const uint64_t length = out.size();
  std::memcpy(out.data() + 12, &kept, sizeof kept);
  std::memcpy(out.data() + 16, &length, sizeof length);
  const uint64_t sum = fnv1a64(out.data(), out.size() - 8);
  std::memcpy(out.data() + out.size() - 8, &sum, sizeof sum);
  return out;
}

// A checkpoint with kept sides but written before their normals (section 16) resumes with no
// side kept, as one written before sides (15): its sides would read as learned on the plane z
// (docs/checkpoint.md). The two resume to the same bits on the CPU and the GPU.
void check_sides_without_normals(const fs::path& dir, const fs::path& scene,
                                 const std::string& args) {
  fs::create_directories(dir);
  const Ran r =
      run(scene, args + " --steps 100 --checkpoint-every 100 --out " + (dir / "at").string(), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string bytes = read_text(dir / "at" / kCheckpointFile);
  ASSERT_FALSE(read_checkpoint(dir / "at" / kCheckpointFile).blade_sides.at(0).empty());
  const std::string old = without_sections(bytes, {checkpoint_format::kSideNormals});
  write_bytes(dir / "old.phx", old);
  EXPECT_TRUE(read_checkpoint(dir / "old.phx").blade_sides.empty());
  std::vector<Checkpoint> ends;
  for (const auto& [name, b] :
       {std::pair{"old", old},
        {"none", without_sections(
                     bytes, {checkpoint_format::kBladeSides, checkpoint_format::kSideNormals})}}) {
    const fs::path to = dir / name;
    fs::remove_all(to);
    fs::copy(dir / "at", to, fs::copy_options::recursive);
    write_bytes(to / kCheckpointFile, b);
    const Ran resumed = run(scene, args + " --steps 200 --resume " + to.string(), dir);
    ASSERT_EQ(resumed.code, 0) << resumed.err;
    ends.push_back(read_checkpoint(to / kCheckpointFile));
  }
  ASSERT_EQ(ends[0].step, 200);
  ASSERT_EQ(ends[0].displacement.size(), ends[1].displacement.size());
  EXPECT_EQ(0, std::memcmp(ends[0].displacement.data(), ends[1].displacement.data(),
                           ends[0].displacement.size() * sizeof(Vec3)));
  EXPECT_EQ(ends[0].severed.size(), ends[1].severed.size());
}

TEST(Checkpoint, SidesWithoutTheirNormalsAreDroppedOnTheCpuAndTheGpu) {
  const fs::path dir = test::test_output_dir("checkpoint_side_normals");
  const fs::path scene = write_scene(dir, "scalpel.json", kScalpel);
  check_sides_without_normals(dir / "cpu", scene, "--threads 1");
  std::string why;
  const std::optional<std::string> gpu_args = gpu_device_args(why);
  if (!gpu_args) GTEST_SKIP() << why;
  check_sides_without_normals(dir / "gpu", scene, *gpu_args);
}

}  // namespace
}  // namespace phyxel
