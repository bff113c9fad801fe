// Tearing on the GPU against the CPU reference (engine/solver/cpu_solver_tearing.cpp): from the
// same overstressed state, one substep tears the same pairs but for those whose stress lies
// within kTearParityTolerance of the threshold, and the positions after agree; two GPU runs of
// a bar pulled apart give the same bits; a phyxel left without a fit loses its last pair as on the
// CPU; without tearing nothing is torn.
#include <set>
#include <utility>

#include "engine/solver/tearing.h"
#include "tests/cutting/cutting_fixtures.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

using phyxel::test::PulledBar;

std::set<std::pair<uint32_t, uint32_t>> pair_set(const std::vector<SeveredPair>& v) {
  std::set<std::pair<uint32_t, uint32_t>> s;
  for (const SeveredPair& p : v) s.insert({p.i, p.j});
  return s;
}

// The bar stretched along x to a stress about 1.25 x its tear stress, with per-phyxel noise so
// that the pairs' stresses spread around the threshold.
void stretched_state(const PhyxelSet& set, std::vector<Vec3>& u, std::vector<Vec3>& v) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> d(-1, 1);
  const double strain = 1.25 * PulledBar::kTearStress / 1e5;  // E = 1e5 Pa
  u.resize(set.size());
  v.assign(set.size(), Vec3::Zero());
  for (size_t i = 0; i < set.size(); ++i)
    u[i] = Vec3(strain * set.rest[i].x(), 0, 0) + 2e-6 * Vec3(d(rng), d(rng), d(rng));
}

// lanes: GpuSolverOptions::lanes (0: auto), which the tear pass shares with the stress pass.
void expect_the_cpus_tears(Context& ctx, uint32_t lanes) {
  const PulledBar bar;
  std::vector<Vec3> u, v;
  stretched_state(bar.set, u, v);
  CpuSolver<double> cpu(bar.set, Vec3::Zero());
  cpu.displacement() = u;
  cpu.velocity() = v;
  cpu.set_tearing(true);
  GpuSolverOptions options;
  options.lanes = lanes;
  GpuSolver gpu(ctx, bar.set, Vec3::Zero(), options);
  gpu.set_state(u, v);
  gpu.set_tearing(true);
  cpu.step(bar.dt);
  cpu.sort_severed_from(0);
  gpu.advance(1, bar.dt);
  const std::vector<SeveredPair> want = cpu.severed_log();
  const std::vector<SeveredPair> got = gpu.severed_since(0);
  ASSERT_GT(want.size(), 50u);
  ASSERT_LT(want.size(), cpu.neighbours().index.size() / 2) << "everything tore";
  for (const SeveredPair& p : got) EXPECT_TRUE(p.torn);
  // Pairs decided differently: only within the documented band of the threshold (the stress
  // from the CPU's state after the step, which is what both decided on).
  const auto c = pair_set(want), g = pair_set(got);
  std::vector<std::pair<uint32_t, uint32_t>> differ;
  std::set_symmetric_difference(c.begin(), c.end(), g.begin(), g.end(), std::back_inserter(differ));
  const double threshold = PulledBar::kTearStress;
  for (const auto& [i, j] : differ) {
    const Vec3 xi = bar.set.rest[i] + cpu.displacement()[i];
    const Vec3 xj = bar.set.rest[j] + cpu.displacement()[j];
    const double s =
        pair_normal_stress<double>(cpu.cauchy_stress()[i], cpu.cauchy_stress()[j], xi, xj);
    EXPECT_LT(std::abs(s - threshold), kTearParityTolerance * threshold)
        << "pair " << i << " " << j << ": s = " << s;
  }
  std::printf("[ tearing  ] %zu pairs torn on the CPU, %zu decided differently\n", want.size(),
              differ.size());
  // The positions after more substeps (tearing further) agree to float precision while the
  // decisions agree.
  if (!differ.empty()) return;
  for (int k = 0; k < 20; ++k) cpu.step(bar.dt);
  gpu.advance(20, bar.dt);
  const std::vector<Vec3> cu = cpu.displacement();
  const std::vector<Vec3> gu = gpu.read_state(false).displacement;
  EXPECT_EQ(pair_set(gpu.severed_since(0)), pair_set(cpu.severed_log()));
  EXPECT_LT(max_difference(cu, gu), 1e-4 * max_norm(cu));
}

TEST_F(GpuSolverTest, TearingFromAnOverstressedStateTearsTheCpusPairs) {
  expect_the_cpus_tears(ctx(), 0);
}

// Four invocations per phyxel share its pairs (the tear pass's lanes on a GPU at small sizes).
TEST_F(GpuSolverTest, TearingWithFourLanesPerPhyxelTearsTheCpusPairs) {
  expect_the_cpus_tears(ctx(), 4);
}

std::pair<std::vector<SeveredPair>, std::vector<Vec3>> pulled_apart(Context& ctx,
                                                                    const PulledBar& bar) {
  GpuSolver gpu(ctx, bar.set, Vec3::Zero());
  gpu.set_tearing(true);
  gpu.set_external_forces(bar.load(0.3));  // three times the tear load, suddenly
  for (int k = 0; k < 10; ++k) gpu.advance(40, bar.dt);
  return {gpu.severed_since(0), gpu.read_state(false).displacement};
}

TEST_F(GpuSolverTest, TwoGpuRunsOfABarPulledApartAreBitIdentical) {
  const PulledBar bar;
  const auto [log_a, u_a] = pulled_apart(ctx(), bar);
  const auto [log_b, u_b] = pulled_apart(ctx(), bar);
  ASSERT_GT(log_a.size(), 10u);
  ASSERT_EQ(log_a.size(), log_b.size());
  for (size_t k = 0; k < log_a.size(); ++k) {
    EXPECT_EQ(log_a[k].i, log_b[k].i) << k;
    EXPECT_EQ(log_a[k].j, log_b[k].j) << k;
    EXPECT_TRUE(log_a[k].torn);
  }
  EXPECT_EQ(u_a, u_b);
}

// A phyxel left without a fit (tearing.h left_without_fit: left with one pair by tears or by
// removals) loses that pair at the next tear pass, at rest, as on the CPU.
TEST_F(GpuSolverTest, APhyxelLeftWithoutAFitLosesItsLastPairAsOnTheCpu) {
  for (const bool torn : {true, false}) {
    const PulledBar bar;
    std::unique_ptr<Solver> cpu = make_cpu_solver(bar.set, Vec3::Zero(), 1, false);
    GpuSolver gpu(ctx(), bar.set, Vec3::Zero());
    cpu->load_changes()->set_external_forces(bar.load(0));  // at rest, unloaded
    gpu.set_external_forces(bar.load(0));
    const auto [p, q] = phyxel::test::leave_one_pair(*cpu, torn);
    EXPECT_EQ(phyxel::test::leave_one_pair(gpu, torn), std::make_pair(p, q));
    const size_t before = gpu.severed_pairs();
    cpu->tearing()->set_tearing(true);
    gpu.set_tearing(true);
    cpu->advance(1, bar.dt);
    gpu.advance(1, bar.dt);
    const std::vector<SeveredPair> got = gpu.severed_since(before);
    ASSERT_EQ(got.size(), 1u) << (torn ? "torn" : "removed");
    EXPECT_EQ(got[0].i, std::min(p, q));
    EXPECT_EQ(got[0].j, std::max(p, q));
    EXPECT_TRUE(got[0].torn);
    EXPECT_EQ(pair_set(gpu.severed_since(0)), pair_set(cpu->cutting()->severed_since(0)));
  }
}

TEST_F(GpuSolverTest, WithoutTearingNothingTearsAndThePassIsNotRecorded) {
  const PulledBar bar;
  GpuSolver gpu(ctx(), bar.set, Vec3::Zero());
  gpu.set_principal_stress(true);
  gpu.set_external_forces(bar.load(0.3));
  gpu.advance(100, bar.dt);
  EXPECT_EQ(gpu.severed_pairs(), 0u);
  bool tear_timed = false;
  for (const PassTime& t : gpu.profile(2, bar.dt)) tear_timed = tear_timed || t.name == "tear";
  EXPECT_FALSE(tear_timed);
  gpu.set_tearing(true);
  gpu.advance(100, bar.dt);
  EXPECT_GT(gpu.severed_pairs(), 0u);
}

}  // namespace
}  // namespace phyxel::gpu::test
