// phyxel bench --stability: long soaks on the CPU in double and float, reporting energy drift,
// the largest speed, the first non-finite value, and float-against-double drift. With a GPU
// device (--device gpu, gpu:N, a name): the soaks that start from rest or from a load pulse,
// driven through the Solver interface on the GPU and on the CPU reference (double), with the
// GPU-against-double drift.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "bench/benches.h"
#include "bench/timing.h"
#include "compute/gpu_solver.h"
#include "engine/geometry/shape.h"
#include "engine/run/simulation.h"

namespace phyxel::bench {
namespace {

struct Soak {
  std::string name;
  Scene scene;
  double dt_fraction;
  Eigen::Matrix3d initial_gradient = Eigen::Matrix3d::Zero();  // u0 = G x0
};

struct SoakResult {
  double energy_drift = 0;  // max |E(t) - E(0)| / |E(0)| (J when E(0) = 0)
  double max_speed = 0;
  int64_t non_finite_step = -1;
  long non_finite_phyxel = -1;
  double seconds = 0;
  std::vector<Vec3> final_u;
};

Scene free_cube() {
  Scene s;
  s.simulation.dt = 1;
  ObjectDesc o;
  o.name = "cube";
  o.shape.type = Shape::Type::Box;
  o.shape.min = Vec3::Zero();
  o.shape.max = Vec3::Constant(0.02);
  o.spacing = 0.0025;
  o.support_radius = 0.005;
  o.material = {1e5, 0.45, 1000, 0, std::nullopt, 0.05, std::nullopt};
  s.objects.push_back(o);
  return s;
}

SoakResult soak(const Soak& c, bool single, int64_t steps, int threads) {
  const PhyxelSet set = sample_scene(c.scene);
  const double dt = c.dt_fraction * plan_time_step(c.scene, set).dt_stable;
  SoakResult r;
  const auto t0 = std::chrono::steady_clock::now();
  // The soak starts from a deformed state u0 = G x0, which the Solver interface cannot set, so
  // it drives the CPU solver types directly.
  std::unique_ptr<CpuSolver<double>> d;
  std::unique_ptr<CpuSolver<float>> f;
  if (single)
    f = std::make_unique<CpuSolver<float>>(set, c.scene.simulation.gravity);
  else
    d = std::make_unique<CpuSolver<double>>(set, c.scene.simulation.gravity);
  for (size_t i = 0; i < set.size(); ++i) {
    const Vec3 u = c.initial_gradient * set.rest[i];
    if (single)
      f->displacement()[i] = u.cast<float>();
    else
      d->displacement()[i] = u;
  }
  if (single)
    f->set_threads(threads), f->compute_forces();
  else
    d->set_threads(threads), d->compute_forces();
  auto energy = [&] { return single ? f->energies().total() : d->energies().total(); };
  const double e0 = energy();
  for (int64_t k = 1; k <= steps; ++k) {
    if (single)
      f->step(float(dt));
    else
      d->step(dt);
    if (k % 100 != 0 && k != steps) continue;
    const long bad = single ? f->first_non_finite() : d->first_non_finite();
    if (bad >= 0) {
      r.non_finite_step = k;
      r.non_finite_phyxel = bad;
      break;
    }
    for (size_t i = 0; i < set.size(); ++i)
      r.max_speed =
          std::max(r.max_speed, single ? double(f->velocity()[i].norm()) : d->velocity()[i].norm());
    if (k % 1000 == 0 || k == steps)
      r.energy_drift = e0 != 0 ? std::max(r.energy_drift, std::abs(energy() - e0) / std::abs(e0))
                               : std::abs(energy());
  }
  r.seconds = seconds_since(t0);
  r.final_u.resize(set.size());
  for (size_t i = 0; i < set.size(); ++i)
    r.final_u[i] = single ? Vec3(f->displacement()[i].cast<double>()) : d->displacement()[i];
  return r;
}

double max_norm(const std::vector<Vec3>& a) {
  double m = 0;
  for (const Vec3& x : a) m = std::max(m, x.norm());
  return m;
}

void add_row(const std::string& soak, const char* label, const std::string& device, int64_t steps,
             const SoakResult& r, nlohmann::json& rows) {
  char bad[64] = "none";
  if (r.non_finite_step >= 0)
    std::snprintf(bad, sizeof bad, "step %lld phyxel %ld",
                  static_cast<long long>(r.non_finite_step), r.non_finite_phyxel);
  std::printf("%-48s %-7s %10lld %12.3e %11.4g %22s %9.2f\n", soak.c_str(), label,
              static_cast<long long>(steps), r.energy_drift, r.max_speed, bad, r.seconds);
  rows.push_back({{"soak", soak},
                  {"real", label},
                  {"device", device},
                  {"steps", steps},
                  {"energy_drift", r.energy_drift},
                  {"max_speed", r.max_speed},
                  {"max_displacement", max_norm(r.final_u)},
                  {"non_finite_step", r.non_finite_step},
                  {"non_finite_phyxel", r.non_finite_phyxel},
                  {"wall_seconds", r.seconds}});
}

double max_difference(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double diff = 0;
  for (size_t i = 0; i < a.size(); ++i) diff = std::max(diff, (a[i] - b[i]).norm());
  return diff;
}

void print_header() {
  std::printf("%-48s %-7s %10s %12s %11s %22s %9s\n", "soak", "real", "steps", "energy drift",
              "max speed", "first non-finite", "wall s");
}

// The free cube squeezed between its top and bottom faces (1 N each way) for 2 ms, then left
// alone: undamped free vibration started from rest, which the Solver interface can do (it
// cannot set u). No net force or torque, so it vibrates in place instead of drifting (a drift
// would grow u and with it the float32 rounding of u_j - u_i on the GPU).
Scene squeezed_cube() {
  Scene s = free_cube();
  for (const double side : {1.0, -1.0}) {
    Load pulse;
    pulse.region.type = Shape::Type::Box;
    pulse.region.min = side > 0 ? Vec3(-1, -1, 0.0199) : Vec3(-1, -1, -1);
    pulse.region.max = side > 0 ? Vec3(1, 1, 1) : Vec3(1, 1, 0.0001);
    pulse.force = Vec3(0, 0, -side);
    pulse.until = 0.002;
    s.objects[0].loads.push_back(pulse);
  }
  return s;
}

// A soak through the Solver interface: the loads switch at their from/until steps (as in
// run_simulation); the energy drift is measured from the state after the last switch so far.
SoakResult soak_solver(Solver& solver, const PhyxelSet& set, double dt, int64_t steps) {
  std::vector<int64_t> events;
  for (const LoadSpread& load : set.loads)
    for (const double t : {load.from, load.until}) {
      if (!(t > 0) || !std::isfinite(t)) continue;
      const auto k = static_cast<int64_t>(std::ceil(t / dt - 1e-9));
      if (k > 0 && k < steps) events.push_back(k);
    }
  std::sort(events.begin(), events.end());
  events.erase(std::unique(events.begin(), events.end()), events.end());
  SoakResult r;
  const auto t0 = std::chrono::steady_clock::now();
  double e0 = solver.energies().total();
  size_t next_event = 0;
  for (int64_t k = 0; k < steps;) {
    int64_t next = std::min(steps, (k / 100 + 1) * 100);
    if (next_event < events.size()) next = std::min(next, events[next_event]);
    solver.advance(next - k, dt);
    k = next;
    if (next_event < events.size() && events[next_event] == k) {
      ++next_event;
      need(solver.load_changes(), solver, "switch loads")
          .set_external_forces(external_forces_at(set, double(k) * dt));
      e0 = solver.energies().total();
    }
    if (k % 100 != 0 && k != steps) continue;
    const long bad = solver.first_non_finite();
    if (bad >= 0) {
      r.non_finite_step = k;
      r.non_finite_phyxel = bad;
      break;
    }
    for (const Vec3& v : solver.read_state(false).velocity)
      r.max_speed = std::max(r.max_speed, v.norm());
    if (k % 1000 == 0 || k == steps) {
      const double e = solver.energies().total();
      r.energy_drift = e0 != 0 ? std::max(r.energy_drift, std::abs(e - e0) / std::abs(e0))
                               : std::max(r.energy_drift, std::abs(e));
    }
  }
  r.seconds = seconds_since(t0);
  r.final_u = solver.read_state(false).displacement;
  return r;
}

int bench_stability_gpu(const std::string& device, int64_t steps, int threads,
                        const std::string& json_file) {
  struct InterfaceSoak {
    std::string name;
    Scene scene;
  };
  const std::vector<InterfaceSoak> soaks = {
      {"demo beam (scenes/beam.json), gravity, damped", load_scene("scenes/beam.json")},
      {"free cube, 2 ms squeeze, undamped, nu 0.45", squeezed_cube()}};
  gpu::ContextOptions context;
  context.device = device;
  context.validation = false;
  nlohmann::json rows = nlohmann::json::array();
  for (const InterfaceSoak& c : soaks) {
    const PhyxelSet set = sample_scene(c.scene);
    const double dt = plan_time_step(c.scene, set).dt_stable;
    const Vec3& gravity = c.scene.simulation.gravity;
    std::unique_ptr<Solver> gpu = make_gpu_solver(set, gravity, context);
    std::unique_ptr<Solver> cpu = make_cpu_solver(set, gravity, threads);
    if (rows.empty()) {
      std::printf("gpu: %s; reference: %s\n", gpu->device().c_str(), cpu->device().c_str());
      print_header();
    }
    const SoakResult g = soak_solver(*gpu, set, dt, steps);
    const SoakResult d = soak_solver(*cpu, set, dt, steps);
    add_row(c.name, "gpu", gpu->device(), steps, g, rows);
    add_row(c.name, "double", cpu->device(), steps, d, rows);
    const double extent = shape_bounds(c.scene.objects[0].shape).sizes().maxCoeff();
    const double diff = max_difference(g.final_u, d.final_u);
    std::printf(
        "  gpu vs double after %lld steps: max |u_gpu - u_d| = %.3e m (%.3e of the extent, "
        "%.3e of max |u_d|)\n",
        static_cast<long long>(steps), diff, diff / extent,
        diff / std::max(max_norm(d.final_u), 1e-300));
    rows[rows.size() - 2]["gpu_vs_double_max_u"] = diff;
    std::fflush(stdout);
  }
  write_json_file(json_file, rows);
  return 0;
}

}  // namespace

int bench_stability(const Args& args) {
  OptionParser opts("bench", args);
  opts.flag("--stability");
  const int64_t steps = opts.integer("--steps", 100000, 1, int64_t(1) << 40);
  const int threads = static_cast<int>(opts.integer("--threads", 0, 0, 1024));
  const std::string device = opts.value("--device", "cpu");  // cpu, gpu, gpu:N or a name
  const std::string json_file = opts.value("--json", "");
  opts.finish();
  if (device != "cpu") return bench_stability_gpu(device, steps, threads, json_file);

  std::vector<Soak> soaks;
  const Eigen::Matrix3d stretch = Eigen::Vector3d(0.2, -0.05, 0.05).asDiagonal();
  soaks.push_back({"free cube, 20 % stretch, nu 0.45, dt 0.5x bound", free_cube(), 0.5, stretch});
  soaks.push_back({"free cube, 20 % stretch, nu 0.45, dt 1.0x bound", free_cube(), 1.0, stretch});
  // Damped and loaded: float and double must stay together here (undamped large vibration is
  // sensitive to rounding like any two nearby trajectories of a nonlinear system).
  soaks.push_back({"demo beam (scenes/beam.json), gravity, damped", load_scene("scenes/beam.json"),
                   1.0, Eigen::Matrix3d::Zero()});
  nlohmann::json rows = nlohmann::json::array();
  print_header();
  for (const Soak& c : soaks) {
    const SoakResult d = soak(c, false, steps, threads);
    const SoakResult f = soak(c, true, steps, threads);
    const Eigen::AlignedBox3d box = shape_bounds(c.scene.objects[0].shape);
    const double extent = box.sizes().maxCoeff();
    const double diff = max_difference(d.final_u, f.final_u);
    add_row(c.name, "double", "cpu", steps, d, rows);
    add_row(c.name, "float", "cpu", steps, f, rows);
    std::printf(
        "  float vs double after %lld steps: max |u_f - u_d| = %.3e m (%.3e of the extent)\n",
        static_cast<long long>(steps), diff, diff / extent);
    rows.back()["float_vs_double_max_u"] = diff;
  }
  write_json_file(json_file, rows);
  return 0;
}

}  // namespace phyxel::bench
