// Tool contact on the GPU against the CPU reference (CpuSolver<double>, which the CPU backend
// runs): a probe presses into a block clamped at its bottom and slides sideways with friction,
// the motions given chunk by chunk (set_tool_motion before each advance) as the run loop does.
// Per-substep tool forces, positions and contact flags agree; a second GPU run gives the same
// bits; a tool that touches nothing changes no bit; a sleeping object takes no contact.
#include <cmath>
#include <cstdio>

#include "engine/geometry/tool.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

// 11 x 9 x 7 = 693 phyxels (not a multiple of 64), the bottom layer fixed, under gravity.
Scene block_scene() {
  Scene scene = lattice_scene(11, 9, 7, tissue(5e4, 0.3, 20.0));
  const double bottom = scene.objects[0].shape.min.z();
  scene.objects[0].fixed.push_back(box_shape(Vec3::Constant(-1), Vec3(1, 1, bottom + 1e-4)));
  scene.simulation.gravity = Vec3(0, 0, -9.81);
  return scene;
}

struct Probe {
  ContactTool tool;
  std::vector<ToolKey> path;
};

// A sphere (r 5 mm) over the middle of the top face, 0.5 mm above it at t = 0: it presses 2 mm
// deep by t1 and slides 4 mm along x by t2, friction 0.3 (other sizes and moves as given).
Probe sphere_probe(const Scene& scene, double t1, double t2, double r = 0.005,
                   double above = 0.0005, double press = 0.002, double slide = 0.004) {
  const Vec3 lo = scene.objects[0].shape.min, hi = scene.objects[0].shape.max;
  const Vec3 top(0.5 * (lo.x() + hi.x()), 0.5 * (lo.y() + hi.y()), hi.z() + r);
  Probe p;
  p.tool.shape = {ToolShape::Type::Sphere, r, 0.0};
  p.tool.friction = 0.3;
  p.path = {{0.0, top + Vec3(0, 0, above), Vec3::UnitZ()},
            {t1, top - Vec3(0, 0, press), Vec3::UnitZ()},
            {t2, top + Vec3(slide, 0, -press), Vec3::UnitZ()}};
  return p;
}

// A capsule (r 3 mm, 30 mm) lying across the top face along y, pressed 1.5 mm deep, then
// turned by 25 degrees about z while it slides along x: the rotation part of the carry.
Probe capsule_probe(const Scene& scene, double t1, double t2) {
  const Vec3 lo = scene.objects[0].shape.min, hi = scene.objects[0].shape.max;
  const double r = 0.003;
  const Vec3 tip(0.5 * (lo.x() + hi.x()), lo.y() - 0.005, hi.z() + r);
  const double a = 25.0 * M_PI / 180.0;
  Probe p;
  p.tool.shape = {ToolShape::Type::Capsule, r, 0.03};
  p.tool.friction = 0.3;
  p.path = {{0.0, tip + Vec3(0, 0, 0.0005), Vec3::UnitY()},
            {t1, tip - Vec3(0, 0, 0.0015), Vec3::UnitY()},
            {t2, tip + Vec3(0.003, 0, -0.0015), Vec3(std::sin(a), std::cos(a), 0)}};
  return p;
}

// A blade with a threshold stabbed point-first (axis +z, r 3 mm) 3 mm into the top face, its
// axis 0.4 mm from the column of lattice sites under the face's middle (inside the friction
// cone of a blunt cap, 0.86 mm), then moved 2 mm along
// x: its point's cap takes no friction (on_sharp_point), its body keeps it. The threshold (10 N)
// is never reached and the edge has no stiffness: contact only, nothing cut or held.
Probe sharp_point_probe(const Scene& scene, double t1, double t2) {
  const Vec3 lo = scene.objects[0].shape.min, hi = scene.objects[0].shape.max;
  const Vec3 tip(0.5 * (lo.x() + hi.x()) + 0.0004, 0.5 * (lo.y() + hi.y()), hi.z() + 0.0005);
  Probe p;
  p.tool.shape = {ToolShape::Type::Capsule, 0.003, 0.02};
  p.tool.friction = 0.3;
  p.tool.blade.length = 0.015;
  p.tool.blade.threshold = 10;
  p.tool.blade.stiffness = 0;
  p.path = {{0.0, tip, Vec3::UnitZ()},
            {t1, tip - Vec3(0, 0, 0.003), Vec3::UnitZ()},
            {t2, tip + Vec3(0.002, 0, -0.003), Vec3::UnitZ()}};
  return p;
}

Probe shifted(Probe p, const Vec3& by) {
  for (ToolKey& k : p.path) k.position += by;
  return p;
}

// Substeps [first, first + n) of the probes' paths: from and to pose of each (substeps x
// probes, row-major).
std::vector<ToolMotion> chunk(const std::vector<Probe>& probes, int64_t first, int64_t n,
                              double dt) {
  std::vector<ToolMotion> m;
  for (int64_t s = 0; s < n; ++s)
    for (const Probe& p : probes)
      m.push_back(
          {pose_at(p.path, double(first + s) * dt), pose_at(p.path, double(first + s + 1) * dt)});
  return m;
}

std::vector<ContactTool> tools_of(const std::vector<Probe>& probes) {
  std::vector<ContactTool> t;
  for (const Probe& p : probes) t.push_back(p.tool);
  return t;
}

struct Trace {
  std::vector<ToolContactSample> samples;  // substeps of every chunk, in order
  std::vector<Vec3> u, v;
  std::vector<uint8_t> contact;
  std::vector<Vec3> cpu_contact_force;  // CPU only: per phyxel, in the last substep
  size_t max_candidates = 0;
};

constexpr int64_t kChunk = 12;  // substeps per advance (the last chunk is shorter)

Trace run_cpu(const PhyxelSet& set, const Vec3& g, const std::vector<Probe>& p, double dt,
              int64_t steps) {
  CpuSolver<double> cpu(set, g);
  cpu.set_threads(1);
  cpu.set_tools(tools_of(p));
  Trace t;
  for (int64_t s = 0; s < steps; s += kChunk) {
    const int64_t n = std::min(kChunk, steps - s);
    cpu.set_tool_motion(chunk(p, s, n, dt), dt);
    for (int64_t k = 0; k < n; ++k) cpu.step(dt);
    t.samples.insert(t.samples.end(), cpu.tool_samples().begin(), cpu.tool_samples().end());
    t.max_candidates = std::max(t.max_candidates, cpu.contact_candidates());
  }
  t.u = cpu.displacement();
  t.v = cpu.velocity();
  t.contact = cpu.contact();
  t.cpu_contact_force = cpu.contact_force();
  return t;
}

Trace run_gpu(Context& ctx, const PhyxelSet& set, const Vec3& g, const std::vector<Probe>& p,
              double dt, int64_t steps) {
  GpuSolver gpu(ctx, set, g);
  EXPECT_NE(gpu.tools(), nullptr);
  gpu.set_tools(tools_of(p));
  Trace t;
  for (int64_t s = 0; s < steps; s += kChunk) {
    const int64_t n = std::min(kChunk, steps - s);
    gpu.set_tool_motion(chunk(p, s, n, dt));
    gpu.advance(n, dt);
    const std::vector<ToolContactSample> felt = gpu.tool_samples();
    EXPECT_EQ(felt.size(), size_t(n) * p.size());
    t.samples.insert(t.samples.end(), felt.begin(), felt.end());
    t.max_candidates = std::max(t.max_candidates, gpu.contact_candidates());
  }
  const PointState s = gpu.read_state(false);
  t.u = s.displacement;
  t.v = s.velocity;
  t.contact = s.contact;
  EXPECT_EQ(gpu.first_non_finite(), -1);
  return t;
}

// The CPU and GPU traces of the probes agree (bounds derived in the comments), and a second GPU
// run is bit-identical. t2: the end of the paths.
// force_scale widens the force bounds for a larger scene (float positions relative to the
// contact frame's centre err in proportion to the scene's size).
void expect_parity(Context& ctx, const std::vector<Probe>& probe, double t2,
                   const Scene& scene = block_scene(), size_t min_candidates = 0,
                   double force_scale = 1.0) {
  const PhyxelSet set = sample_scene(scene);
  const Vec3 g = scene.simulation.gravity;
  const double dt = plan_time_step(scene, set).dt_stable;
  const int64_t steps = static_cast<int64_t>(std::ceil(t2 / dt));
  const Trace cpu = run_cpu(set, g, probe, dt, steps);
  const Trace gpu = run_gpu(ctx, set, g, probe, dt, steps);
  ASSERT_EQ(gpu.samples.size(), cpu.samples.size());
  EXPECT_EQ(gpu.max_candidates, cpu.max_candidates);  // the same broad phase
  EXPECT_GE(gpu.max_candidates, min_candidates);

  // A real contact: many phyxels touched, a peak force, friction felt while sliding.
  double peak = 0, peak_tangential = 0;
  uint32_t peak_contacts = 0;
  for (const ToolContactSample& s : cpu.samples) {
    peak = std::max(peak, s.force.norm());
    peak_tangential = std::max(peak_tangential, std::abs(s.force.x()));
    peak_contacts = std::max(peak_contacts, s.contacts);
  }
  ASSERT_GE(peak_contacts, 5u);
  for (size_t t = 0; t < probe.size(); ++t) {  // every tool touches (samples: substep x tool)
    uint32_t contacts = 0;
    for (size_t k = t; k < cpu.samples.size(); k += probe.size())
      contacts += cpu.samples[k].contacts;
    EXPECT_GT(contacts, 0u) << "tool " << t;
  }
  ASSERT_GT(peak, 0);
  EXPECT_GT(peak_tangential, 0.05 * peak);

  // Tool forces per substep. A sample sums m dv / dt over the contacts; dv is of the order of
  // the tool's speed, and the float32 state agrees with the double one to about 1e-6 of its
  // size (CpuSolver<float> against CpuSolver<double> on this scene: 2.4e-6 of the peak force
  // at worst; the GPU measured 1.4e-6 for the sphere and 4.4e-6 for the turning capsule on
  // lavapipe). The positions relative to the chunk's origin keep the penetration depths in
  // float to about 1e-10 m. Bounds: 2e-4 of the peak per substep, 2e-5 on average (a phyxel
  // that enters contact one substep apart would cost about 1e-2 and fails them).
  double worst = 0, mean_diff = 0;
  Vec3 sum_diff = Vec3::Zero();
  size_t count_mismatch = 0;
  for (size_t k = 0; k < cpu.samples.size(); ++k) {
    const Vec3 d = gpu.samples[k].force - cpu.samples[k].force;
    worst = std::max(worst, d.norm());
    mean_diff += d.norm();
    sum_diff += d;
    const int dc = int(gpu.samples[k].contacts) - int(cpu.samples[k].contacts);
    if (dc != 0) ++count_mismatch;
    EXPECT_LE(std::abs(dc), 1) << "substep " << k;
  }
  mean_diff /= double(cpu.samples.size());
  std::printf(
      "[ contact  ] %zu samples, peak %.4g N (%u contacts), worst |dF| %.3g of the peak, "
      "mean %.3g, drift of the summed impulse %.3g; %zu samples with other counts\n",
      cpu.samples.size(), peak, peak_contacts, worst / peak, mean_diff / peak,
      sum_diff.norm() / (peak * double(cpu.samples.size())), count_mismatch);
  EXPECT_LE(worst, 2e-4 * force_scale * peak);
  EXPECT_LE(mean_diff, 2e-5 * force_scale * peak);
  EXPECT_LE(count_mismatch, cpu.samples.size() / 50);  // measured: none

  // The contacts' range along the tool's axis (a blade's penetration depth): where both solvers
  // count the same contacts, the same phyxels span it, so it differs by their positions' float
  // error (the contact projection puts them on the surface to about 1e-7 m); a phyxel at the
  // end of the range that enters contact one substep apart would cost about a spacing (1e-3 m).
  const AxialAgreement axial = axial_agreement(
      cpu.samples, gpu.samples, 1e-5, [](const ToolContactSample& c, const ToolContactSample& g) {
        return c.contacts > 0 && g.contacts == c.contacts;
      });
  std::printf("[ contact  ] axial range of %zu samples: worst %.3g m, %zu beyond 1e-5 m\n",
              axial.compared, axial.worst, axial.outliers);
  EXPECT_GT(axial.compared, 0u);
  EXPECT_EQ(axial.empty_on_cpu, 0u);  // every contact lies somewhere along the axis
  EXPECT_LE(axial.outliers, axial.compared / 50);

  // Positions: the damped parity test allows 1e-3 of the largest displacement over 1000 steps;
  // here 1e-4 (measured 6e-7 for the sphere, 5.5e-6 for the capsule).
  const double u_scale = max_norm(cpu.u);
  const double du = max_difference(gpu.u, cpu.u);
  std::printf("[ contact  ] max |u| %.4g m, max |u_gpu - u_cpu| %.3g of it\n", u_scale,
              du / u_scale);
  EXPECT_LE(du, 1e-4 * u_scale);

  // Contact flags of the last substep: equal, except where the CPU's phyxel lies within the
  // solvers' disagreement of the tool's surface; every phyxel that the CPU pressed with more
  // than 1e-3 of the largest contact force is touched on the GPU too.
  double f_max = 0;
  for (const Vec3& f : cpu.cpu_contact_force) f_max = std::max(f_max, f.norm());
  size_t touched = 0, differ = 0;
  for (size_t i = 0; i < set.size(); ++i) {
    touched += cpu.contact[i];
    if (cpu.contact[i] == gpu.contact[i]) continue;
    ++differ;
    double phi = 1e300;  // to the nearest tool at its last end pose
    for (const Probe& p : probe) {
      const ToolPose end = pose_at(p.path, double(steps) * dt);
      phi = std::min(phi, tool_distance(p.tool.shape, end, set.rest[i] + cpu.u[i]).distance);
    }
    EXPECT_LE(std::abs(phi), std::max(du, 1e-9)) << "phyxel " << i;
    EXPECT_LE(cpu.cpu_contact_force[i].norm(), 1e-3 * f_max) << "phyxel " << i;
  }
  std::printf("[ contact  ] %zu phyxels touched in the last substep, %zu flags differ\n", touched,
              differ);
  EXPECT_GT(touched, 0u);
  for (size_t i = 0; i < set.size(); ++i)
    if (set.flags[i] & kFixed) {
      EXPECT_EQ(gpu.contact[i], 0);
    }

  // The same bits again.
  const Trace again = run_gpu(ctx, set, g, probe, dt, steps);
  for (size_t k = 0; k < gpu.samples.size(); ++k) {
    ASSERT_EQ(again.samples[k].force, gpu.samples[k].force) << "substep " << k;
    ASSERT_EQ(again.samples[k].contacts, gpu.samples[k].contacts) << "substep " << k;
    ASSERT_EQ(again.samples[k].axial_min, gpu.samples[k].axial_min) << "substep " << k;
    ASSERT_EQ(again.samples[k].axial_max, gpu.samples[k].axial_max) << "substep " << k;
  }
  for (size_t i = 0; i < set.size(); ++i) {
    ASSERT_EQ(again.u[i], gpu.u[i]) << "phyxel " << i;
    ASSERT_EQ(again.v[i], gpu.v[i]) << "phyxel " << i;
  }
  EXPECT_EQ(again.contact, gpu.contact);
}

TEST_F(GpuSolverTest, ContactSphereProbePressAndSlideMatchesTheCpu) {
  expect_parity(ctx(), {sphere_probe(block_scene(), 0.03, 0.06)}, 0.06);
}

TEST_F(GpuSolverTest, ContactTurningCapsuleMatchesTheCpu) {
  expect_parity(ctx(), {capsule_probe(block_scene(), 0.025, 0.05)}, 0.05);
}

// The sharp point (on_sharp_point, tool_contact.glsl's kind.y): the same contacts on both
// solvers, and on the CPU other than the same capsule's without a blade (friction on its cap).
TEST_F(GpuSolverTest, ContactSharpPointMatchesTheCpu) {
  const Scene scene = block_scene();
  const Probe sharp = sharp_point_probe(scene, 0.03, 0.05);
  expect_parity(ctx(), {sharp}, 0.05);
  Probe blunt = sharp;
  blunt.tool.blade = Blade{};
  const PhyxelSet set = sample_scene(scene);
  const double dt = plan_time_step(scene, set).dt_stable;
  const int64_t steps = static_cast<int64_t>(std::ceil(0.05 / dt));
  const Trace a = run_cpu(set, scene.simulation.gravity, {sharp}, dt, steps);
  const Trace b = run_cpu(set, scene.simulation.gravity, {blunt}, dt, steps);
  const double differ = max_difference(a.u, b.u);
  std::printf("[ contact  ] sharp against blunt point: max |du| %.3g m\n", differ);
  EXPECT_GT(differ, 1e-6);
}

// Two tools at once (the per-tool reduction and sample layout): the sphere 7 mm to the side of
// the turning capsule, each feeling its own force.
TEST_F(GpuSolverTest, ContactTwoToolsAtOnceMatchTheCpu) {
  const Scene scene = block_scene();
  expect_parity(ctx(),
                {shifted(sphere_probe(scene, 0.025, 0.05), Vec3(-0.007, 0, 0)),
                 capsule_probe(scene, 0.025, 0.05)},
                0.05);
}

// A tool whose candidates it never touches (hovering 0.5 mm over the block), and one out of
// reach (no candidates, no contact pass): the same bits as a solver without tools, zero samples.
// tool_contact sums each workgroup's candidates and tool_contact_reduce adds the workgroups'
// partials, 64 at a time per thread: a sphere of 10 cm radius over a plate of 70 x 70 x 3
// phyxels takes its whole top layer as candidates (4 900, more than 64 x 64), so threads of the
// reduction add several partials each. The plate is 6.4 times the block's width, so the force
// bounds are 5 times wider (measured on lavapipe: worst 6.9e-5, mean 2.0e-5 of the peak).
TEST_F(GpuSolverTest, ContactForcesOverMoreThan4096CandidatesMatchTheCpu) {
  Scene scene = lattice_scene(70, 70, 3, tissue(5e4, 0.3, 20.0));
  const double bottom = scene.objects[0].shape.min.z();
  scene.objects[0].fixed.push_back(box_shape(Vec3::Constant(-1), Vec3(1, 1, bottom + 1e-4)));
  scene.simulation.gravity = Vec3(0, 0, -9.81);
  const Probe p = sphere_probe(scene, 0.008, 0.012, 0.1, 0.0002, 0.001, 0.001);
  expect_parity(ctx(), {p}, 0.012, scene, 64 * 64 + 1, 5.0);
}

TEST_F(GpuSolverTest, ContactToolThatTouchesNothingChangesNoBit) {
  const Scene scene = block_scene();
  const PhyxelSet set = sample_scene(scene);
  const Vec3 g = scene.simulation.gravity;
  const double dt = plan_time_step(scene, set).dt_stable;
  Probe hover = sphere_probe(scene, 1.0, 2.0);
  hover.path.resize(1);  // rests 0.5 mm above the top face
  Probe away = hover;
  away.path[0].position.z() += 1.0;
  GpuSolver plain(ctx(), set, g);
  GpuSolver near(ctx(), set, g), far(ctx(), set, g);
  near.set_tools({hover.tool});
  far.set_tools({away.tool});
  for (int k = 0; k < 3; ++k) {
    plain.advance(7, dt);
    for (auto [solver, probe] : {std::pair{&near, &hover}, std::pair{&far, &away}}) {
      solver->set_tool_motion(chunk({*probe}, 7 * k, 7, dt));
      solver->advance(7, dt);
      ASSERT_EQ(solver->tool_samples().size(), 7u);
      for (const ToolContactSample& s : solver->tool_samples()) {
        EXPECT_EQ(s.contacts, 0u);
        EXPECT_EQ(s.force, Vec3::Zero());
      }
    }
  }
  EXPECT_GT(near.contact_candidates(), 0u);
  EXPECT_EQ(far.contact_candidates(), 0u);
  const PointState a = plain.read_state(false);
  for (GpuSolver* solver : {&near, &far}) {
    const PointState b = solver->read_state(false);
    for (size_t i = 0; i < set.size(); ++i) {
      ASSERT_EQ(b.displacement[i], a.displacement[i]) << "phyxel " << i;
      ASSERT_EQ(b.velocity[i], a.velocity[i]) << "phyxel " << i;
      ASSERT_EQ(b.contact[i], 0) << "phyxel " << i;
    }
  }
  // The pass plan: no contact pass without tools; with a tool in reach tool_contact after the
  // first drift, the force pass's contact after the others (contact_in_force), their rows
  // summed after the last.
  auto names = [](const std::vector<PassTime>& times) {
    std::vector<std::string> out;
    for (const PassTime& t : times) out.push_back(t.name);
    return out;
  };
  const std::vector<std::string> without = names(plain.profile(3, dt));
  near.set_tool_motion(chunk({hover}, 21, 3, dt));
  const std::vector<std::string> with = names(near.profile(3, dt));
  if (PassTimer(ctx()).supported()) {  // lavapipe has timestamps
    EXPECT_EQ(without, (std::vector<std::string>{"kick_drift", "stress", "force"}));
    EXPECT_EQ(with, (std::vector<std::string>{"kick_drift", "contact", "stress", "force+contact",
                                              "force", "contact: rows"}));
  }
}

// A sleeping object takes no contact (the candidates are those of awake objects, refiltered
// when an object sleeps or wakes); the CPU's broad phase drops it too.
// A fast tool sweeping over the block 1.5 spacings above it, the tissue at rest: the broad
// phase's margin grows with the tool's speed (contact_margin) on the GPU as on the CPU.
TEST_F(GpuSolverTest, ContactBroadPhaseMarginGrowsWithTheToolsSpeedAsOnTheCpu) {
  const Scene scene = block_scene();
  const PhyxelSet set = sample_scene(scene);
  const double dt = plan_time_step(scene, set).dt_stable;
  const Vec3 lo = scene.objects[0].shape.min, hi = scene.objects[0].shape.max;
  const double r = 0.005, h = hi.z() + r + 1.5 * scene.objects[0].spacing;
  Probe sweep = sphere_probe(scene, 1.0, 2.0);
  const double y = 0.5 * (lo.y() + hi.y());
  sweep.path = {{0.0, Vec3(lo.x() - 0.01, y, h), Vec3::UnitZ()},
                {0.01, Vec3(hi.x() + 0.01, y, h), Vec3::UnitZ()}};
  const int64_t first = static_cast<int64_t>(0.005 / dt), n = 8;
  ASSERT_GT(tool_speed({sweep.tool}, chunk({sweep}, first, n, dt), dt) * 2 * double(n) * dt,
            scene.objects[0].spacing);  // the speed term reaches the surface
  GpuSolver gpu(ctx(), set, scene.simulation.gravity);
  gpu.set_tools({sweep.tool});
  gpu.set_tool_motion(chunk({sweep}, first, n, dt));
  gpu.advance(n, dt);
  CpuSolver<double> cpu(set, scene.simulation.gravity);
  cpu.set_tools({sweep.tool});
  cpu.set_tool_motion(chunk({sweep}, first, n, dt), dt);
  EXPECT_GT(cpu.contact_candidates(), 0u);
  EXPECT_EQ(gpu.contact_candidates(), cpu.contact_candidates());
}

// A diverging state (an infinite speed, so an infinite margin) takes every phyxel that
// can take contact into the broad phase, as contact_candidates does on the CPU, never none.
TEST_F(GpuSolverTest, ContactBroadPhaseOfADivergingStateTakesEveryMovingPhyxel) {
  const Scene scene = block_scene();
  const PhyxelSet set = sample_scene(scene);
  const Vec3 g = scene.simulation.gravity;
  const double dt = plan_time_step(scene, set).dt_stable;
  const Probe probe = sphere_probe(scene, 1.0, 2.0);
  size_t moving = 0;
  for (const uint32_t f : set.flags) moving += (f & (kFixed | kRemoved)) ? 0 : 1;
  ASSERT_GT(moving, 10u);
  std::vector<Vec3> u(set.size(), Vec3::Zero()), v(set.size(), Vec3::Zero());
  for (size_t i = 0; i < set.size(); ++i)
    if (!(set.flags[i] & kFixed)) {
      v[i] = Vec3(std::numeric_limits<double>::infinity(), 0, 0);
      break;
    }
  GpuSolver gpu(ctx(), set, g);
  gpu.set_tools({probe.tool});
  gpu.set_state(u, v);
  gpu.set_tool_motion(chunk({probe}, 0, 2, dt));
  gpu.advance(2, dt);
  EXPECT_EQ(gpu.contact_candidates(), moving);
  CpuSolver<double> cpu(set, g);
  cpu.set_tools({probe.tool});
  cpu.velocity() = v;
  cpu.set_tool_motion(chunk({probe}, 0, 2, dt), dt);
  EXPECT_EQ(cpu.contact_candidates(), moving);
}

TEST_F(GpuSolverTest, ContactLeavesASleepingObjectAlone) {
  const Scene scene = block_scene();
  const PhyxelSet set = sample_scene(scene);
  const Vec3 g = scene.simulation.gravity;
  const double dt = plan_time_step(scene, set).dt_stable;
  Probe deep = sphere_probe(scene, 1.0, 2.0);
  deep.path.resize(1);
  deep.path[0].position.z() -= 0.002;  // 1.5 mm inside the top face from the start
  GpuSolver gpu(ctx(), set, g);
  gpu.set_tools({deep.tool});
  gpu.advance(5, dt);  // no motion yet: no contact, no samples (as the CPU)
  EXPECT_TRUE(gpu.tool_samples().empty());
  gpu.set_object_awake(0, false);
  const PointState before = gpu.read_state(false);
  gpu.set_tool_motion(chunk({deep}, 0, 9, dt));
  gpu.advance(9, dt);
  EXPECT_EQ(gpu.contact_candidates(), 0u);
  ASSERT_EQ(gpu.tool_samples().size(), 9u);
  for (const ToolContactSample& s : gpu.tool_samples()) EXPECT_EQ(s.contacts, 0u);
  const PointState after = gpu.read_state(false);
  for (size_t i = 0; i < set.size(); ++i) {
    ASSERT_EQ(after.displacement[i], before.displacement[i]) << "phyxel " << i;
    ASSERT_EQ(after.contact[i], 0) << "phyxel " << i;
  }
  CpuSolver<double> cpu(set, g);
  cpu.set_tools({deep.tool});
  cpu.set_object_awake(0, false);
  cpu.set_tool_motion(chunk({deep}, 0, 9, dt), dt);
  EXPECT_EQ(cpu.contact_candidates(), 0u);
  // Woken, the chunk's candidates come back (the broad phase runs again at the next advance)
  // and the probe pushes the block out of itself; past the chunk's motions it stays at the
  // last end pose.
  gpu.set_object_awake(0, true);
  gpu.advance(4, dt);
  EXPECT_GT(gpu.contact_candidates(), 0u);
  uint32_t contacts = 0;
  for (const ToolContactSample& s : gpu.tool_samples()) contacts += s.contacts;
  EXPECT_GT(contacts, 0u);
  const PointState woken = gpu.read_state(false);
  size_t flagged = 0;
  for (uint8_t c : woken.contact) flagged += c;
  EXPECT_GT(flagged, 0u);
}

}  // namespace
}  // namespace phyxel::gpu::test
