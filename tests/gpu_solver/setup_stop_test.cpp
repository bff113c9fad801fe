// The GPU solver's setup (neighbour search, MLS precompute) runs in chunks of phyxels and polls
// the setup's stop (set_search_stop, which Ctrl-C and SIGTERM set) before each: a stop ends it
// with SearchStopped naming the phase, as the CPU's; the chunk size changes no bit.
#include <atomic>
#include <cstring>

#include "engine/solver/neighbours.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

// Chunked passes of the setup: cells, scatter, pair count, pair fill (the search), precompute.
constexpr int kSearchPhases = 4;
// Phyxels per chunk: not a multiple of the workgroup size.
constexpr uint32_t kChunk = 50;

struct StopGuard {
  ~StopGuard() { set_search_stop({}); }
};

GpuSolverOptions chunked(uint32_t phyxels) {
  GpuSolverOptions options;
  options.setup_chunk = phyxels;
  return options;
}

bool same_bits(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3)) == 0;
}

TEST_F(GpuSolverTest, SetupChunksGiveTheSameBitsAndPollTheStopBeforeEach) {
  const StopGuard guard;
  const PhyxelSet set = lattice(13, 11, 9);
  const int chunks = int((set.size() + kChunk - 1) / kChunk);
  ASSERT_GT(chunks, 10);
  std::atomic<int> polls{0};
  set_search_stop([&] { return ++polls < 0; });
  GpuSolver small(ctx(), set, Vec3(0, 0, -9.81), chunked(kChunk));
  EXPECT_EQ(polls.load(), (kSearchPhases + 1) * chunks);
  set_search_stop({});
  GpuSolver whole(ctx(), set, Vec3(0, 0, -9.81), chunked(uint32_t(set.size())));
  EXPECT_EQ(small.neighbours().offset, whole.neighbours().offset);
  EXPECT_EQ(small.neighbours().index, whole.neighbours().index);
  EXPECT_EQ(small.neighbours().index, find_rest_neighbours(set).index);
  const std::vector<MomentInverseRow> a = small.moment_inverses(), b = whole.moment_inverses();
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(std::memcmp(a[i].inverse, b[i].inverse, sizeof a[i].inverse), 0) << "phyxel " << i;
    EXPECT_EQ(a[i].regularised, b[i].regularised) << "phyxel " << i;
  }
  small.advance(20, 1e-4);
  whole.advance(20, 1e-4);
  const PointState sa = small.read_state(false), sb = whole.read_state(false);
  EXPECT_TRUE(same_bits(sa.displacement, sb.displacement));
  EXPECT_TRUE(same_bits(sa.velocity, sb.velocity));
}

TEST_F(GpuSolverTest, AStopDuringTheSetupEndsItAtTheNextChunk) {
  const StopGuard guard;
  const PhyxelSet set = lattice(13, 11, 9);
  const int chunks = int((set.size() + kChunk - 1) / kChunk);
  std::atomic<int> polls{0};
  // Asked for in the middle of the pair count (the third pass), then at the precompute's first.
  for (const int stop_after : {2 * chunks + 3, kSearchPhases * chunks}) {
    polls = 0;
    set_search_stop([&] { return ++polls > stop_after; });
    try {
      GpuSolver solver(ctx(), set, Vec3::Zero(), chunked(kChunk));
      ADD_FAILURE() << "the setup did not stop";
    } catch (const SearchStopped& e) {
      EXPECT_STREQ(e.what(), stop_after < kSearchPhases * chunks
                                 ? "stopped during the neighbour search"
                                 : "stopped during the MLS precompute");
    }
    EXPECT_EQ(polls.load(), stop_after + 1);  // nothing submitted after the stop
  }
  set_search_stop({});
  const GpuSolver after(ctx(), set, Vec3::Zero(), chunked(kChunk));  // the context is fine
  EXPECT_EQ(after.neighbours().index, find_rest_neighbours(set).index);
}

}  // namespace
}  // namespace phyxel::gpu::test
