// Cutting on the GPU against the CPU reference (engine/solver/cpu_solver_cutting.cpp): the
// same severed pairs and positions after a scalpel crosses a beam, with the tools' motions
// given chunk by chunk as the run loop does; two blades severing the same pairs in the same
// substeps give each pair once, to the CPU's tool, and a second blade through the first's cut
// severs the CPU's pairs; two GPU runs give the same bits; a cut along a lattice plane and a
// second crossing cut leave every value finite; blades past the first 8 (no ball around them)
// sever as the CPU; tool_resist summing its own samples, and tool_contact_reduce summing them
// beside the sever, give the bits of the passes they replace, and so does the sever beside the
// stress pass; a chunk whose candidates all lie beyond the blades' reach dispatches no sever,
// as the CPU tests no pair then.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <tuple>
#include <utility>

#include "engine/surgery/tool_track.h"
#include "tests/cutting/cutting_fixtures.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

using phyxel::test::clamped_beam;
using phyxel::test::crossing_scalpel;

struct CutRun {
  std::vector<SeveredPair> severed;
  std::vector<Vec3> u;
  std::vector<uint8_t> alive;
  size_t candidates = 0;
  std::vector<ToolContactSample> samples;  // every substep's
  std::vector<uint8_t> near;               // per chunk: Tools::blades_near
  std::vector<size_t> listed;              // per chunk: Tools::contact_candidates
};

CutRun run(Solver& solver, const Scene& scene, int64_t steps, int64_t chunk = 16) {
  ToolTrack track(scene.tools, {});
  Tools& tools = *solver.tools();
  tools.set_tools(contact_tools(scene.tools));
  const double dt = scene.simulation.dt;
  CutRun out;
  for (int64_t s = 0; s < steps; s += chunk) {
    const int64_t n = std::min(chunk, steps - s);
    tools.set_tool_motion(track.motions(s, n, dt));
    solver.advance(n, dt);
    out.candidates = std::max(out.candidates, tools.contact_candidates());
    out.near.push_back(tools.blades_near() ? 1 : 0);
    out.listed.push_back(tools.contact_candidates());
    const std::vector<ToolContactSample> felt = tools.tool_samples();
    out.samples.insert(out.samples.end(), felt.begin(), felt.end());
  }
  out.severed = solver.cutting()->severed_since(0);
  out.u = solver.read_state(false).displacement;
  out.alive = solver.cutting()->pair_alive();
  return out;
}

std::set<std::pair<uint32_t, uint32_t>> pair_set(const std::vector<SeveredPair>& v) {
  std::set<std::pair<uint32_t, uint32_t>> s;
  for (const SeveredPair& p : v) s.insert({p.i, p.j});
  return s;
}

// The scene's run on the CPU, then on the GPU.
std::pair<CutRun, CutRun> cpu_and_gpu(Context& ctx, const Scene& scene, int64_t steps) {
  const PhyxelSet set = sample_scene(scene);
  auto cpu = make_cpu_solver(set, scene.simulation.gravity, 1);
  GpuSolver gpu(ctx, set, scene.simulation.gravity);
  CutRun c = run(*cpu, scene, steps);
  return {std::move(c), run(gpu, scene, steps)};
}

TEST_F(GpuSolverTest, CuttingABeamSeversTheCpusPairsAndMovesAlike) {
  Scene scene = clamped_beam();
  scene.tools.push_back(crossing_scalpel(0.009, -0.003, 0.016, 0.002, 0.016));
  const auto [c, g] = cpu_and_gpu(ctx(), scene, 400);
  ASSERT_GT(c.severed.size(), 100u);
  EXPECT_EQ(pair_set(g.severed), pair_set(c.severed));
  EXPECT_EQ(g.alive, c.alive);
  for (size_t k = 0; k < std::min(c.severed.size(), g.severed.size()); ++k)
    EXPECT_NEAR(g.severed[k].t, c.severed[k].t, 1e-4) << k;
  // The free piece falls: positions agree to float precision of the fall.
  const double scale = max_norm(c.u);
  EXPECT_GT(scale, 1e-3);
  EXPECT_LT(max_difference(c.u, g.u), 1e-4 * scale);
  // The blade's axial range in the tissue (its penetration depth, cut_feedback.h): the same but
  // for a phyxel at the edge of the band around the blade in a few substeps (a spacing's jump).
  ASSERT_EQ(g.samples.size(), c.samples.size());
  const AxialAgreement axial = axial_agreement(
      c.samples, g.samples, 1e-5, [](const ToolContactSample& cs, const ToolContactSample& gs) {
        return cs.axial_min <= cs.axial_max || gs.axial_min <= gs.axial_max;  // either has one
      });
  std::printf("[ cutting  ] blade range in %zu substeps: worst %.3g m, %zu beyond 1e-5 m\n",
              axial.compared, axial.worst, axial.outliers);
  EXPECT_GT(axial.compared, 100u);
  EXPECT_LE(axial.outliers, axial.compared / 50);
}

// tool_sever tests a candidate's pairs in parallel lanes (32 for this beam's few hundred
// candidates: fewer than the 80 pairs of a support radius of 2.5 spacings), both sides of a pair
// at once: two parallel blades 0.3 mm apart cross the same pairs in the same substeps. Every pair
// is severed once (none dropped, none twice) and goes to the first tool, as on the CPU (its t is
// that blade's crossing).
TEST_F(GpuSolverTest, TwoBladesOnTheSamePairsSeverEachOnceAsTheCpu) {
  Scene scene = clamped_beam();
  scene.simulation.gravity = Vec3::Zero();
  scene.objects[0].support_radius = 2.5 * scene.objects[0].spacing;
  // Off the lattice's planes and the substeps' grid (a pair's crossing on the line between two
  // substeps' quads is a tie that float and double may give to different substeps, and so to
  // the other blade).
  for (const double x : {0.00931, 0.00963}) {
    ToolDesc blade = crossing_scalpel(x, -0.003, 0.016, 0.0, 0.008);
    blade.name = scene.tools.empty() ? "first" : "second";
    for (ToolKey& key : blade.path) key.position.y() -= 7.3e-5;
    scene.tools.push_back(blade);
  }
  const auto [c, g] = cpu_and_gpu(ctx(), scene, 120);
  ASSERT_GT(c.severed.size(), 500u);
  EXPECT_EQ(pair_set(c.severed).size(), c.severed.size());
  EXPECT_EQ(pair_set(g.severed).size(), g.severed.size());  // none twice
  EXPECT_EQ(pair_set(g.severed), pair_set(c.severed));
  EXPECT_EQ(g.alive, c.alive);
  // Sorted per advance on both: the same pairs in the same places, each with the first
  // blade's t (the second's differs by 0.3 mm over the pair's span along x).
  ASSERT_EQ(g.severed.size(), c.severed.size());
  for (size_t k = 0; k < c.severed.size(); ++k) {
    EXPECT_EQ(g.severed[k].i, c.severed[k].i) << k;
    EXPECT_EQ(g.severed[k].j, c.severed[k].j) << k;
    EXPECT_NEAR(g.severed[k].t, c.severed[k].t, 1e-4) << k;
  }
  EXPECT_LT(max_difference(c.u, g.u), 1e-4 * std::max(max_norm(c.u), 1e-6));  // and finite
}

// tool_sever loads each lane's candidate and first pair before the blades' balls are set up
// (its weight and index together), the lane's later pairs in its loop: a second blade through
// the first's cut finds the pairs it crosses severed (weight 0, a lane's first pair among them),
// rows of up to 80 pairs on 32 lanes and some lanes without a pair. It severs the CPU's pairs,
// none twice.
TEST_F(GpuSolverTest, ASecondBladeThroughTheFirstsCutSeversTheCpusPairs) {
  Scene scene = clamped_beam();
  scene.simulation.gravity = Vec3::Zero();
  scene.objects[0].support_radius = 2.5 * scene.objects[0].spacing;
  for (const double t0 : {0.0, 0.01}) {
    ToolDesc blade = crossing_scalpel(t0 > 0.0 ? 0.00934 : 0.00931, -0.003, 0.016, t0, 0.008);
    blade.name = t0 > 0.0 ? "second" : "first";
    scene.tools.push_back(blade);
  }
  const auto [c, g] = cpu_and_gpu(ctx(), scene, 200);
  ASSERT_GT(c.severed.size(), 500u);
  EXPECT_EQ(pair_set(g.severed).size(), g.severed.size());  // none twice
  EXPECT_EQ(pair_set(g.severed), pair_set(c.severed));
  EXPECT_EQ(g.alive, c.alive);
  EXPECT_LT(max_difference(c.u, g.u), 1e-4 * std::max(max_norm(c.u), 1e-6));
}

// tool_sever tests a pair against a blade only where it meets the ball around all that blade
// can sever in the substep, for the first 8 tools (kSeverBallTools); a later tool's blade tests
// every pair. Nine scalpels: the first and the ninth cross the beam at x = 9 and 25 mm, the
// seven between pass 0.5 m away. Both cuts sever the CPU's pairs.
TEST_F(GpuSolverTest, BladesWithAndWithoutTheirBallSeverTheCpusPairs) {
  Scene scene = clamped_beam();
  scene.simulation.gravity = Vec3::Zero();
  for (int k = 0; k < 9; ++k) {
    ToolDesc blade = crossing_scalpel(k == 8 ? 0.025 : 0.009, -0.003, 0.016, 0.0, 0.008);
    blade.name = "scalpel " + std::to_string(k);
    if (k > 0 && k < 8)
      for (ToolKey& key : blade.path) key.position.z() += 0.5;
    scene.tools.push_back(blade);
  }
  const PhyxelSet set = sample_scene(scene);
  const auto [c, g] = cpu_and_gpu(ctx(), scene, 120);
  size_t near_first = 0, near_ninth = 0;
  for (const SeveredPair& p : c.severed) {
    const double x = 0.5 * (set.rest[p.i].x() + set.rest[p.j].x());
    near_first += std::abs(x - 0.009) < 0.004;
    near_ninth += std::abs(x - 0.025) < 0.004;
  }
  EXPECT_GT(near_first, 100u);
  EXPECT_GT(near_ninth, 100u);
  EXPECT_EQ(pair_set(g.severed), pair_set(c.severed));
  EXPECT_EQ(g.alive, c.alive);
}

TEST_F(GpuSolverTest, CuttingBelowAndAboveTheThresholdMatchesTheCpu) {
  Scene scene = clamped_beam();
  scene.simulation.gravity = Vec3::Zero();
  // A blade pressing 1 mm into the side: it feels well under 1 N (no cut), then a sharper
  // one that cuts once the force passes 0.02 N.
  scene.tools.push_back(crossing_scalpel(0.02, -0.003, 0.016, 0.0, 0.016, 1.0));
  scene.tools[0].path[1].position.y() = 0.004;
  const PhyxelSet set = sample_scene(scene);
  {
    GpuSolver gpu(ctx(), set, scene.simulation.gravity);
    EXPECT_TRUE(run(gpu, scene, 300).severed.empty());
  }
  scene.tools[0].blade.threshold = 0.02;
  auto cpu = make_cpu_solver(set, scene.simulation.gravity, 1);
  GpuSolver gpu(ctx(), set, scene.simulation.gravity);
  const CutRun c = run(*cpu, scene, 300);
  const CutRun g = run(gpu, scene, 300);
  EXPECT_GT(c.severed.size(), 0u);
  EXPECT_EQ(pair_set(g.severed), pair_set(c.severed));
}

// The edge's resistance (docs/cutting.md): the pairs a blade with a threshold has passed push
// it back alike on both solvers, below the threshold (100 N) only the pairs its edge carries
// past its reach separate, the same on both, and once the
// force reaches half the largest it felt below, the same pairs are severed; at a twentieth,
// where a phyxel's push reaches the threshold (bounded_edge_push), too.
void expect_resistance_parity(Context& ctx, Scene scene) {
  const PhyxelSet set = sample_scene(scene);
  double peak = 0;
  for (const double share : {0.0, 0.5, 0.05}) {
    const bool cuts = share > 0;
    SCOPED_TRACE(cuts ? "above the threshold" : "below it");
    scene.tools[0].blade.threshold = cuts ? share * peak : 100.0;
    auto cpu = make_cpu_solver(set, scene.simulation.gravity, 1);
    GpuSolver gpu(ctx, set, scene.simulation.gravity);
    const CutRun c = run(*cpu, scene, 96);
    const CutRun g = run(gpu, scene, 96);
    ASSERT_EQ(g.samples.size(), c.samples.size());
    double worst = 0, largest = 0;
    for (size_t k = 0; k < c.samples.size(); ++k) {
      worst = std::max(worst, (g.samples[k].force - c.samples[k].force).norm());
      largest = std::max(largest, c.samples[k].force.norm());
    }
    std::printf("[ resist   ] force on the blade up to %.4g N, GPU - CPU up to %.3g N\n", largest,
                worst);
    EXPECT_GT(largest, 0.01);
    EXPECT_LT(worst, 1e-3 * largest);
    if (!cuts) {  // only the pairs the edge carried past its reach (edge_passes)
      peak = largest;
      EXPECT_EQ(pair_set(g.severed), pair_set(c.severed));
    } else {
      EXPECT_GT(c.severed.size(), 20u);
      EXPECT_EQ(pair_set(g.severed), pair_set(c.severed));
    }
    EXPECT_LT(max_difference(c.u, g.u), 1e-3 * max_norm(c.u));
  }
}

TEST_F(GpuSolverTest, TheEdgesResistanceAndItsCutsMatchTheCpu) {
  Scene scene = clamped_beam(5e4, 5);
  scene.simulation.gravity = Vec3::Zero();
  scene.tools.push_back(crossing_scalpel(0.021, -0.003, 0.016, 0.0, 0.016));
  expect_resistance_parity(ctx(), scene);
}

// A blade turned about a point 6 mm from its tip, inside the beam: below that point it moves
// backwards and is held against its own motion there.
TEST_F(GpuSolverTest, ATurnedBladesResistanceMatchesTheCpu) {
  Scene scene = clamped_beam(5e4, 5);
  scene.simulation.gravity = Vec3::Zero();
  ToolDesc t = crossing_scalpel(0.021, -0.003, 0.016, 0.0, 0.016);
  const Vec3 pivot(0.021, 0.004, 0.003);
  t.path.clear();
  for (int k = 0; k <= 8; ++k) {
    const double a = 0.5 * k / 8;  // rad, about x
    const Vec3 axis(0, std::sin(a), std::cos(a));
    t.path.push_back({0.016 * k / 8, pivot - 0.006 * axis, axis});
  }
  scene.tools.push_back(t);
  expect_resistance_parity(ctx(), scene);
}

// A blade that never reaches its threshold (100 N) across the whole beam: the pairs its edge
// carries past its reach are severed whatever the force (edge_passes), the same pairs on both
// solvers, crossing the blade's plane at the same place.
TEST_F(GpuSolverTest, PairsCarriedPastTheEdgesReachAreSeveredAsOnTheCpu) {
  Scene scene = clamped_beam(5e4, 5);
  scene.simulation.gravity = Vec3::Zero();
  scene.tools.push_back(crossing_scalpel(0.021, -0.003, 0.016, 0.0, 0.016, 100.0));
  const auto [c, g] = cpu_and_gpu(ctx(), scene, 150);
  std::printf("[ cutting  ] %zu pairs carried past the reach severed on the CPU, %zu on the GPU\n",
              c.severed.size(), g.severed.size());
  EXPECT_GT(c.severed.size(), 50u);
  EXPECT_EQ(pair_set(g.severed), pair_set(c.severed));
  EXPECT_EQ(g.alive, c.alive);
  std::vector<SeveredPair> cs = c.severed, gs = g.severed;
  const auto by_pair = [](const SeveredPair& a, const SeveredPair& b) {
    return a.i != b.i ? a.i < b.i : a.j < b.j;
  };
  std::sort(cs.begin(), cs.end(), by_pair);
  std::sort(gs.begin(), gs.end(), by_pair);
  for (size_t k = 0; k < std::min(cs.size(), gs.size()); ++k) EXPECT_NEAR(gs[k].t, cs[k].t, 1e-4);
  EXPECT_LT(max_difference(c.u, g.u), 1e-3 * max_norm(c.u));
}

TEST_F(GpuSolverTest, TwoGpuRunsOfACutGiveTheSameBits) {
  Scene scene = clamped_beam();
  scene.tools.push_back(crossing_scalpel(0.013, -0.003, 0.016, 0.0, 0.02));
  const PhyxelSet set = sample_scene(scene);
  GpuSolver a(ctx(), set, scene.simulation.gravity);
  GpuSolver b(ctx(), set, scene.simulation.gravity);
  const CutRun ra = run(a, scene, 300, 64);
  const CutRun rb = run(b, scene, 300, 64);
  ASSERT_GT(ra.severed.size(), 0u);
  ASSERT_EQ(ra.severed.size(), rb.severed.size());
  for (size_t k = 0; k < ra.severed.size(); ++k) {
    EXPECT_EQ(ra.severed[k].i, rb.severed[k].i);
    EXPECT_EQ(ra.severed[k].j, rb.severed[k].j);
    EXPECT_EQ(ra.severed[k].t, rb.severed[k].t);
  }
  for (size_t i = 0; i < ra.u.size(); ++i) ASSERT_EQ(ra.u[i], rb.u[i]) << i;
  EXPECT_EQ(a.pair_weights(), b.pair_weights());
}

// A blade through the whole beam in one substep: hundreds of phyxels in the dirty list, more
// than tool_sever's last workgroup has lanes (it reruns their precompute in rounds, where a
// short list gets several lanes per phyxel): the CPU's pairs, and its motion after.
TEST_F(GpuSolverTest, ACutThroughTheBeamInOneSubstepMatchesTheCpu) {
  Scene scene = clamped_beam();
  scene.objects[0].spacing = 0.001;
  scene.objects[0].support_radius = 0.0025;
  scene.simulation.dt = 5e-5;
  scene.tools.push_back(crossing_scalpel(0.0093, -0.003, 0.016, 0.0005, 5e-5));
  const auto [c, g] = cpu_and_gpu(ctx(), scene, 40);
  std::set<uint32_t> dirty;
  for (const SeveredPair& p : c.severed) dirty.insert({p.i, p.j});
  std::printf("[ cutting  ] %zu pairs of %zu phyxels severed in one substep\n", c.severed.size(),
              dirty.size());
  ASSERT_GT(dirty.size(), 300u);
  EXPECT_EQ(pair_set(g.severed), pair_set(c.severed));
  EXPECT_EQ(g.alive, c.alive);
  const double scale = max_norm(c.u);
  EXPECT_GT(scale, 1e-6);
  EXPECT_LT(max_difference(c.u, g.u), 1e-4 * scale);
}

// A blade that keeps sides through `scene` for `steps` on both solvers: the same pairs severed,
// the positions within 1e-3 (the contact moves kept phyxels out of the body toward their sides
// alike: kept_side_exit), and the same sides kept, learned on the same planes; no phyxel cut
// free unless `may_free` (a long turn: sides lapse, docs/cutting.md). The CPU's sides.
std::vector<BladeSide> expect_same_sides(Context& ctx, const Scene& scene, int64_t steps,
                                         const PhyxelSet& set, bool may_free = false) {
  auto cpu = make_cpu_solver(set, scene.simulation.gravity, 1);
  GpuSolver gpu(ctx, set, scene.simulation.gravity);
  const CutRun c = run(*cpu, scene, steps, 50);
  const CutRun g = run(gpu, scene, steps, 50);
  EXPECT_GT(c.severed.size(), 60u);
  EXPECT_EQ(pair_set(g.severed), pair_set(c.severed));
  EXPECT_LT(max_difference(c.u, g.u), 1e-3 * max_norm(c.u));
  const NeighbourLists& nbr = gpu.neighbours();
  size_t freed = 0;  // the same on both solvers, which sever the same pairs
  for (uint32_t i = 0; i < set.size(); ++i) {
    bool live = false;
    for (uint32_t k = nbr.offset[i]; k < nbr.offset[i + 1]; ++k) live = live || g.alive[k];
    freed += !live;
    EXPECT_TRUE(live || may_free) << "phyxel " << i << " cut free";
  }
  std::printf("[ sides    ] %zu pairs severed, %zu phyxels cut free\n", c.severed.size(), freed);
  const auto sides_c = cpu->cutting()->blade_sides(), sides_g = gpu.blade_sides();
  EXPECT_EQ(sides_c.size(), 1u);
  EXPECT_EQ(sides_g.size(), 1u);
  if (sides_c.size() != 1 || sides_g.size() != 1 || sides_g[0].size() != sides_c[0].size()) {
    ADD_FAILURE() << "the GPU keeps other sides than the CPU";
    return {};
  }
  for (size_t k = 0; k < sides_c[0].size(); ++k) {
    const BladeSide &sc = sides_c[0][k], &sg = sides_g[0][k];
    EXPECT_EQ(sg.phyxel, sc.phyxel);
    EXPECT_EQ(sg.side, sc.side) << "phyxel " << sc.phyxel;
    EXPECT_GT(unpack_side_normal(sg.normal).dot(unpack_side_normal(sc.normal)), 0.99999)
        << "phyxel " << sc.phyxel;
  }
  return sides_c[0];
}

// A scalpel_cut-like block (2 mm, 5 kPa, fixed below 1.5 mm) and a blade at 0.02 N (body 0.4 mm)
// on `path`, oriented by `edge` where it does not move sideways.
Scene sided_block(const Vec3& lo, const Vec3& hi, const std::vector<ToolKey>& path,
                  const Vec3& edge) {
  Scene scene = phyxel::test::box_scene(lo, hi, 0.002, phyxel::test::tissue(5000, 0.45, 20));
  scene.objects[0].fixed.push_back(phyxel::test::box_shape(Vec3(-1, -1, -1), Vec3(1, 1, 0.0015)));
  scene.simulation.dt = 2.4e-4;
  ToolDesc blade = crossing_scalpel(0, 0.003, 0.02, 0.0, 0.1, 0.02);
  blade.shape.radius = 0.0004;
  blade.path = path;
  blade.blade.edge = edge;
  scene.tools.push_back(blade);
  return scene;
}

// A phyxel on the blade's plane keeps one side (docs/cutting.md, "One side per phyxel"): a cut
// along the lattice plane y = 0 of a scalpel_cut-like block severs the same pairs on both
// solvers, keeps the same sides, frees no phyxel, and the sides come back as they were put.
TEST_F(GpuSolverTest, ABladeKeepsEachPhyxelOnOneSideAsTheCpuDoes) {
  // The lattice 20 um off the blade's plane (outside the float-double tie band, which the
  // plane itself would be): the body pushes the phyxels there across it.
  Scene scene = sided_block(
      Vec3(-0.008, -0.00398, 0), Vec3(0.008, 0.00402, 0.008),
      {{0.0, Vec3(-0.012, 0, 0.003), Vec3::UnitZ()}, {0.1, Vec3(0.004, 0, 0.003), Vec3::UnitZ()}},
      Vec3::UnitX());
  const PhyxelSet set = sample_scene(scene);
  const std::vector<BladeSide> kept = expect_same_sides(ctx(), scene, 300, set);
  EXPECT_GT(kept.size(), 20u);
  GpuSolver resumed(ctx(), set, scene.simulation.gravity);
  resumed.set_tools(contact_tools(scene.tools));
  resumed.restore_blade_sides({kept});
  const auto back = resumed.blade_sides();
  ASSERT_EQ(back.size(), 1u);
  ASSERT_EQ(back[0].size(), kept.size());
  for (size_t k = 0; k < back[0].size(); ++k) {
    EXPECT_EQ(back[0][k].side, kept[k].side) << "phyxel " << back[0][k].phyxel;
    EXPECT_EQ(back[0][k].normal, kept[k].normal) << "phyxel " << back[0][k].phyxel;
  }
}

// The cutting state (docs/cutting.md, "Rupture and the cutting state"): a blade at 0.02 N along
// the block, stopped half-way for 30 ms and moved on, ruptures the tissue, cuts while it moves,
// leaves the state when it stops and ruptures again. Both solvers sever the same pairs and are in
// the same state stopped and moving; the state comes back as it was put.
TEST_F(GpuSolverTest, ABladesRuptureAndCuttingStateMatchTheCpu) {
  const Scene scene = sided_block(Vec3(-0.008, -0.00398, 0), Vec3(0.008, 0.00402, 0.008),
                                  {{0.0, Vec3(-0.012, 0, 0.003), Vec3::UnitZ()},
                                   {0.04, Vec3(-0.004, 0, 0.003), Vec3::UnitZ()},
                                   {0.07, Vec3(-0.004, 0, 0.003), Vec3::UnitZ()},
                                   {0.12, Vec3(0.004, 0, 0.003), Vec3::UnitZ()}},
                                  Vec3::UnitX());
  const PhyxelSet set = sample_scene(scene);
  std::vector<size_t> severed;
  std::vector<uint8_t> cutting;
  for (const int64_t steps : {200, 360, 420, 480}) {  // 48 ms: stopped; then moving again
    auto cpu = make_cpu_solver(set, scene.simulation.gravity, 1);
    GpuSolver gpu(ctx(), set, scene.simulation.gravity);
    const CutRun c = run(*cpu, scene, steps, 40);
    const CutRun g = run(gpu, scene, steps, 40);
    EXPECT_EQ(pair_set(g.severed), pair_set(c.severed)) << steps;
    const std::vector<uint8_t> state = cpu->cutting()->blades_cutting();
    EXPECT_EQ(gpu.blades_cutting(), state) << steps;
    ASSERT_EQ(state.size(), 1u);
    severed.push_back(c.severed.size());
    cutting.push_back(state[0]);
  }
  std::printf("[ rupture  ] pairs %zu %zu %zu %zu, cutting %d %d %d %d\n", severed[0], severed[1],
              severed[2], severed[3], cutting[0], cutting[1], cutting[2], cutting[3]);
  EXPECT_GT(severed[0], 20u);         // ruptured and cut before the stop
  EXPECT_EQ(cutting[0], 0);           // stopped: out of the cutting state
  EXPECT_GT(severed[3], severed[0]);  // moved on: ruptured again and cut
  EXPECT_TRUE(cutting[1] || cutting[2] || cutting[3]);
  GpuSolver resumed(ctx(), set, scene.simulation.gravity);
  resumed.set_tools(contact_tools(scene.tools));
  EXPECT_EQ(resumed.blades_cutting(), std::vector<uint8_t>{0});
  resumed.restore_blades_cutting({1});
  EXPECT_EQ(resumed.blades_cutting(), std::vector<uint8_t>{1});
}

// A blade that keeps sides turned along an arc (radius 5.1 mm, 115 degrees of it about a
// vertical axis in 400 steps): its plane turns under the phyxels beside the arc, which stay
// candidates for tens of degrees, so their sides lapse once it has turned past kSideTurn from
// the plane they were learned on (docs/cutting.md, "The plane a side was learned on"): the
// sides kept at the end were learned on planes within 2 kSideTurn of each other. Both solvers
// sever the same pairs and keep the same sides, learned on the same planes; both cut the same
// 3 phyxels free. The keys are 7 degrees apart: the plane is the chord's, so it turns by a key's
// step at each key, and at 10 degrees (kSideTurn) every lapse was a tie, cos of the turn within
// 7e-7 of cos kSideTurn, under the 16-bit normal's rounding (5e-6), which float and double
// decided apart (4 pairs by 400 steps). At 7 degrees the nearest is 2.6e-4 from it.
TEST_F(GpuSolverTest, ATurnedBladesSidesLapseAsOnTheCpu) {
  std::vector<ToolKey> arc;
  for (int k = 0; k <= 18; ++k) {
    const double a = k * 7 * M_PI / 180;  // 120 degrees in 0.1 s
    arc.push_back({0.1 * k * 7 / 120, Vec3(0.0051 * std::cos(a), 0.0051 * std::sin(a), 0.003),
                   Vec3::UnitZ()});
  }
  const Scene scene =
      sided_block(Vec3(-0.00898, -0.00898, 0), Vec3(0.00902, 0.00902, 0.008), arc, Vec3::UnitY());
  const std::vector<BladeSide> kept =
      expect_same_sides(ctx(), scene, 400, sample_scene(scene), true);
  double widest = 1;  // the least cosine between two kept sides' planes
  for (const BladeSide& a : kept)
    for (const BladeSide& b : kept)
      widest = std::min(widest, unpack_side_normal(a.normal).dot(unpack_side_normal(b.normal)));
  std::printf("[ sides    ] %zu sides kept, on planes up to %.1f deg apart\n", kept.size(),
              std::acos(std::min(widest, 1.0)) * 180 / M_PI);
  EXPECT_GT(kept.size(), 2u);
  EXPECT_GT(widest, std::cos(2 * kSideTurn + 0.01));
}

TEST_F(GpuSolverTest, CutsAlongALatticePlaneAndAcrossEachOtherStayFinite) {
  Scene scene = clamped_beam();
  scene.tools.push_back(crossing_scalpel(0.010, -0.003, 0.016, 0.0, 0.016));  // lattice plane
  ToolDesc second = crossing_scalpel(0.0, -0.003, 0.016, 0.02, 0.02);
  second.name = "second";
  second.path = {{0.02, Vec3(0.002, 0.005, -0.003), Vec3::UnitZ()},
                 {0.04, Vec3(0.03, 0.005, -0.003), Vec3::UnitZ()}};
  second.blade.edge = Vec3::UnitX();
  scene.tools.push_back(second);
  const PhyxelSet set = sample_scene(scene);
  GpuSolver gpu(ctx(), set, scene.simulation.gravity);
  const CutRun g = run(gpu, scene, 600, 64);
  EXPECT_GT(g.severed.size(), 0u);
  EXPECT_EQ(gpu.first_non_finite(), -1);
  EXPECT_TRUE(std::isfinite(gpu.energies().total()));
}

// The clamped beam without gravity, a blade with `threshold` crossing it and jaws (tool 1)
// that close on its free end at 3 ms and pull it 1 mm.
Scene cut_and_pull(double threshold) {
  Scene scene = clamped_beam(5e4, 5);
  scene.simulation.gravity = Vec3::Zero();
  scene.tools.push_back(crossing_scalpel(0.021, -0.003, 0.016, 0.0, 0.016, threshold));
  ToolDesc jaws;
  jaws.name = "jaws";
  jaws.type = ToolDesc::Type::Grasper;
  jaws.shape.radius = 0.0005;
  jaws.grasp.reach = 0.003;
  jaws.grasp.from = 0.0002;
  jaws.path = {{0.0, Vec3(0.039, 0.005, 0.005), Vec3::UnitZ()},
               {0.003, Vec3(0.039, 0.005, 0.005), Vec3::UnitZ()},
               {0.0096, Vec3(0.040, 0.005, 0.005), Vec3::UnitZ()}};
  scene.tools.push_back(jaws);
  return scene;
}

// 96 steps of `scene` with `base` (the default options) and with `other`: the same severed
// pairs, u, grip and samples, to the bit.
void expect_the_same_bits(Context& ctx, const Scene& scene, const GpuSolverOptions& other,
                          const char* tag, const GpuSolverOptions& base = {}) {
  const PhyxelSet set = sample_scene(scene);
  GpuSolver a(ctx, set, scene.simulation.gravity, base);
  GpuSolver b(ctx, set, scene.simulation.gravity, other);
  const CutRun f = run(a, scene, 96);
  const CutRun s = run(b, scene, 96);
  EXPECT_GT(f.severed.size(), 20u);
  EXPECT_GT(a.held_phyxels(1).size(), 4u);
  EXPECT_EQ(a.held_phyxels(1), b.held_phyxels(1));
  EXPECT_EQ(pair_set(f.severed), pair_set(s.severed));
  ASSERT_EQ(f.severed.size(), s.severed.size());
  for (size_t k = 0; k < f.severed.size(); ++k) EXPECT_EQ(f.severed[k].t, s.severed[k].t) << k;
  EXPECT_EQ(f.alive, s.alive);
  ASSERT_EQ(f.u.size(), s.u.size());
  for (size_t i = 0; i < f.u.size(); ++i) ASSERT_EQ(f.u[i], s.u[i]) << i;
  ASSERT_EQ(f.samples.size(), s.samples.size());
  double largest = 0;
  for (size_t k = 0; k < f.samples.size(); ++k) {
    EXPECT_EQ(f.samples[k].force, s.samples[k].force) << k;
    EXPECT_EQ(f.samples[k].contacts, s.samples[k].contacts) << k;
    EXPECT_EQ(f.samples[k].held, s.samples[k].held) << k;
    EXPECT_EQ(f.samples[k].axial_min, s.samples[k].axial_min) << k;
    EXPECT_EQ(f.samples[k].axial_max, s.samples[k].axial_max) << k;
    largest = std::max(largest, f.samples[k].force.norm());
  }
  EXPECT_GT(largest, 0.01);
  std::printf("[ %-8s ] %zu pairs severed, %zu held, force up to %.4g N: the same bits\n", tag,
              f.severed.size(), a.held_phyxels(1).size(), largest);
}

// tool_resist summing the samples itself (GpuSolverOptions::resist_reduce) against
// tool_contact_reduce after it: the same bits, while a threshold blade cuts the beam and a
// grasper holds and pulls its free end (its hold after the edge's resistance, in its own pass).
TEST_F(GpuSolverTest, ResistSummingItsOwnSamplesGivesTheBitsOfTheReducePass) {
  Scene scene = cut_and_pull(100.0);
  double peak = 0;  // the blade's largest force below the threshold, as the parity test's
  {
    GpuSolver gpu(ctx(), sample_scene(scene), scene.simulation.gravity);
    for (const ToolContactSample& s : run(gpu, scene, 96).samples)
      peak = std::max(peak, s.force.norm());
  }
  scene.tools[0].blade.threshold = 0.05 * peak;
  GpuSolverOptions own;
  own.resist_reduce = false;
  expect_the_same_bits(ctx(), scene, own, "resist");
}

// The samples summed beside the sever (GpuSolverOptions::sums_apart: tool_contact_reduce, with
// the grip's forces) against tool_contact's last workgroup: the same bits, while a blade
// without a threshold cuts the beam and the jaws (their hold inside tool_contact, their own
// passes on the substep they close) pull its free end.
TEST_F(GpuSolverTest, SamplesSummedBesideTheSeverGiveTheBitsOfTheLastWorkgroup) {
  GpuSolverOptions last;
  last.sums_apart = false;
  expect_the_same_bits(ctx(), cut_and_pull(0.0), last, "apart");
}

// The contact and the jaws' hold inside the force pass (GpuSolverOptions::contact_in_force
// without tearing: solver_force_contact, the grip rows; tool_contact on the substep the jaws
// close) against tool_contact after it: the same bits, while a blade without a threshold cuts
// the beam and the jaws pull its free end.
TEST_F(GpuSolverTest, ContactAndHoldInTheForcePassGiveToolContactsBits) {
  const Scene scene = cut_and_pull(0.0);
  GpuSolver gpu(ctx(), sample_scene(scene), scene.simulation.gravity);
  run(gpu, scene, 48);
  bool fused = false;
  for (const PassTime& t : gpu.profile(2, scene.simulation.dt))
    fused = fused || t.name == "force+contact";
  EXPECT_TRUE(fused) << "the contact was not in the force pass";
  GpuSolverOptions after;
  after.contact_in_force = false;
  expect_the_same_bits(ctx(), scene, after, "in force");
}

// The sever beside the stress pass (GpuSolverOptions::sever_beside_stress: its last workgroup
// redoes the stress of the phyxels it cut pairs of) against its own pass between the force and
// stress passes: the same bits, with 4 lanes a phyxel (the redo's order of the sums), for a
// blade without a threshold and one with (kept sides), while the jaws pull the beam's end.
TEST_F(GpuSolverTest, TheSeverBesideTheStressPassGivesTheBitsOfItsOwnPass) {
  GpuSolverOptions beside;
  beside.lanes = 4;
  GpuSolverOptions own = beside;
  own.sever_beside_stress = false;
  Scene scene = cut_and_pull(0.0);
  double peak = 0;  // the blade's largest force, for a threshold it reaches
  {
    GpuSolver gpu(ctx(), sample_scene(scene), scene.simulation.gravity, beside);
    for (const ToolContactSample& s : run(gpu, scene, 48).samples)
      peak = std::max(peak, s.force.norm());
    bool fused = false;
    for (const PassTime& t : gpu.profile(2, scene.simulation.dt))
      fused = fused || t.name == "stress+cut";
    EXPECT_TRUE(fused) << "the sever was not beside the stress pass";
  }
  expect_the_same_bits(ctx(), scene, own, "beside", beside);
  scene.tools[0].blade.threshold = 0.05 * peak;
  expect_the_same_bits(ctx(), scene, own, "sided", beside);
}

// The scalpel parked 3 cm from the beam, then crossing it, while the jaws hold its end: the
// chunks whose candidates (the jaws') all lie beyond the blade's reach dispatch no sever
// (tool_broad_scan) where the CPU tests no pair, the same chunks on both; then the same cut.
// A blade with a threshold keeps sides: its pass takes every candidate, near or not (none
// without one).
TEST_F(GpuSolverTest, ChunksBeyondTheBladesReachSeverNothingAsOnTheCpu) {
  Scene scene = cut_and_pull(0.0);
  scene.tools[0].path = {{0.0, Vec3(0.021, -0.03, -0.003), Vec3::UnitZ()},
                         {0.0048, Vec3(0.021, -0.03, -0.003), Vec3::UnitZ()},
                         {0.0208, Vec3(0.021, 0.013, -0.003), Vec3::UnitZ()}};
  auto [c, g] = cpu_and_gpu(ctx(), scene, 240);
  ASSERT_EQ(c.near.size(), 15u);
  std::printf("[ near     ] blades near in chunks:");
  for (size_t k = 0; k < g.near.size(); ++k) std::printf(" %d(%zu)", g.near[k], g.listed[k]);
  std::printf("; %zu pairs severed\n", g.severed.size());
  EXPECT_EQ(g.near, c.near);
  EXPECT_EQ(g.listed, c.listed);
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(g.near[k], 0) << "chunk " << k;
    EXPECT_GT(g.listed[k], 0u) << "chunk " << k << ": the jaws' candidates";
  }
  EXPECT_EQ(g.near.back(), 1);
  EXPECT_GT(c.severed.size(), 20u);
  EXPECT_EQ(pair_set(g.severed), pair_set(c.severed));
  EXPECT_EQ(g.alive, c.alive);
  scene.tools[0].blade.threshold = 1e-3;
  std::tie(c, g) = cpu_and_gpu(ctx(), scene, 48);
  EXPECT_EQ(g.near, std::vector<uint8_t>(3, 1));
  EXPECT_EQ(c.near, g.near);
  scene.tools.pop_back();  // no jaws: no candidate while the blade is parked, no sever
  std::tie(c, g) = cpu_and_gpu(ctx(), scene, 48);
  EXPECT_EQ(g.listed, std::vector<size_t>(3, 0));
  EXPECT_EQ(g.near, std::vector<uint8_t>(3, 0));
  EXPECT_EQ(c.near, g.near);
}

}  // namespace
}  // namespace phyxel::gpu::test
