#include "engine/run/validation.h"

#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "engine/run/simulation.h"
#include "engine/surgery/tool_track.h"

namespace phyxel {
namespace {

nlohmann::json calculix(const std::filesystem::path& file, const char* generator) {
  std::ifstream in(file);
  if (!in)
    throw std::runtime_error(file.string() +
                             ": cannot open the CalculiX reference; regenerate it with "
                             "scenes/validation/ccx/" +
                             generator);
  return nlohmann::json::parse(in);
}

double calculix_tip(const std::filesystem::path& file, const char* which) {
  return calculix(file, "make_cantilever_reference.sh")["cases"][which]["results"]["tip_center_uz"]
      .get<double>();
}

// Indices of the phyxels whose rest position has coordinate `axis` within tol of `at`.
std::vector<size_t> layer(const PhyxelSet& set, int axis, double at, double tol) {
  std::vector<size_t> out;
  for (size_t i = 0; i < set.size(); ++i)
    if (std::abs(set.rest[i][axis] - at) < tol) out.push_back(i);
  return out;
}

// The phyxel at p, allowing for the rounding of a spacing scale like 4/3 written 1.333333.
size_t phyxel_at(const PhyxelSet& set, const Vec3& p, const std::string& scene) {
  const double tol = 0.01 * set.objects.at(0).spacing;
  for (size_t i = 0; i < set.size(); ++i)
    if ((set.rest[i] - p).norm() < tol) return i;
  throw std::runtime_error(scene +
                           ": no phyxel at the probe point; use a spacing that puts "
                           "a lattice point there");
}

// Steps a damped scene to rest: until its kinetic energy falls below 1e-10 of its peak, or,
// once below 1e-7 of it, stops falling (the float32 solver reaches a rounding floor there;
// the displacement has then settled to far better than the validation tolerances).
int64_t relax(Solver& solver, double dt, int64_t max_steps) {
  double peak = 0, last = std::numeric_limits<double>::infinity();
  const int64_t chunk = 100, min_steps = 2000, window = 20;  // window: chunks between looks
  int64_t chunks = 0;
  for (int64_t done = 0; done < max_steps; done += chunk) {
    solver.advance(chunk, dt);
    const double ke = solver.energies().kinetic;
    peak = std::max(peak, ke);
    if (!std::isfinite(ke)) return done + chunk;
    if (done >= min_steps && ke < 1e-10 * peak) return done + chunk;
    if (++chunks % window == 0) {
      if (done >= min_steps && ke < 1e-7 * peak && ke > 0.5 * last) return done + chunk;
      last = ke;
    }
  }
  return max_steps;
}

// The mean u_z of the phyxels within 0.75 spacings of p: the four around the tip's centre
// line when the lattice puts none on it (an odd number of spacings across the section).
double mean_uz_around(const PhyxelSet& set, const PointState& s, const Vec3& p,
                      const std::string& scene) {
  const double radius = 0.75 * set.objects.at(0).spacing;
  double sum = 0;
  int count = 0;
  for (size_t i = 0; i < set.size(); ++i)
    if ((set.rest[i] - p).norm() < radius) sum += s.displacement[i].z(), ++count;
  if (count == 0)
    throw std::runtime_error(scene + ": no phyxel within 0.75 spacings of the tip's centre");
  return sum / count;
}

// The slit case: the scene's scalpels cut the beam at rest (no gravity) along their paths, then
// gravity is applied as a load and the beam relaxes.
void cut_then_load(Solver& solver, const Scene& scene, const PhyxelSet& set, double dt) {
  double duration = 0;
  for (const ToolDesc& t : scene.tools) duration = std::max(duration, t.path.back().t);
  const int64_t steps = static_cast<int64_t>(std::ceil(duration / dt)) + 1, chunk = 16;
  ToolTrack track(scene.tools, {});
  Tools& tools = need(solver.tools(), solver, "simulate tools");
  tools.set_tools(contact_tools(scene.tools));
  for (int64_t s = 0; s < steps; s += chunk) {
    const int64_t n = std::min(chunk, steps - s);
    tools.set_tool_motion(track.motions(s, n, dt));
    solver.advance(n, dt);
  }
  tools.set_tools({});
  std::vector<Vec3> loads(set.size());
  for (size_t i = 0; i < set.size(); ++i)
    loads[i] = set.mass[i] * scene.simulation.gravity + set.external_force[i];
  need(solver.load_changes(), solver, "switch loads").set_external_forces(loads);
}

double mean_x_velocity(const PointState& s, const std::vector<size_t>& idx) {
  double sum = 0;
  for (size_t i : idx) sum += s.velocity[i].x();
  return sum / static_cast<double>(idx.size());
}

}  // namespace

std::vector<ValidationCase> validation_cases(const std::filesystem::path& source_dir) {
  const std::filesystem::path dir = source_dir / "scenes/validation";
  const std::filesystem::path ccx = dir / "cantilever_reference.json";
  std::vector<ValidationCase> cases;
  cases.push_back({"cantilever_small", dir / "cantilever_small.json", "tip u_z (m)",
                   calculix_tip(ccx, "A"), "CalculiX C3D20R 40x8x8, linear"});
  cases.push_back({"cantilever_large", dir / "cantilever_large.json", "tip u_z (m)",
                   calculix_tip(ccx, "C-nl"), "CalculiX C3D20R 40x8x8, NLGEOM"});
  const nlohmann::json slit =
      calculix(dir / "cantilever_slit_reference.json", "make_slit_reference.sh");
  cases.push_back({"cantilever_slit", dir / "cantilever_slit.json", "tip u_z (m)",
                   slit["results"]["slit"].get<double>(),
                   "CalculiX C3D20R " + slit["convergence"].back()["mesh"].get<std::string>() +
                       ", linear, slit as duplicated nodes"});
  const Scene bar = load_scene(dir / "uniaxial_bar.json");
  cases.push_back({"uniaxial_bar", bar.file, "Young's modulus (Pa)", bar.objects[0].material.young,
                   "closed form: E and nu of the material"});
  const Scene wave = load_scene(dir / "wave_bar.json");
  cases.push_back({"wave_bar", wave.file, "wave front speed (m/s)",
                   p_wave_speed(wave.objects[0].material),
                   "closed form: c_p = sqrt((lambda + 2 mu) / rho), nu = 0"});
  return cases;
}

ValidationRun run_validation(const ValidationCase& c, double spacing_scale, double dt_fraction,
                             const SolverFactory& make_solver) {
  Scene scene = load_scene(c.scene);
  ObjectDesc& obj = scene.objects.at(0);
  obj.support_radius *= spacing_scale;
  obj.spacing *= spacing_scale;
  const PhyxelSet set = sample_scene(scene);
  const double dt = dt_fraction * plan_time_step(scene, set).dt_stable;

  ValidationRun run;
  run.case_name = c.name;
  run.spacing = obj.spacing;
  run.dt = dt;
  run.dt_fraction = dt_fraction;
  run.phyxels = set.size();
  run.reference = c.reference;
  const auto start = std::chrono::steady_clock::now();
  const bool slit = c.name == "cantilever_slit";  // loaded after the cut: no gravity until then
  std::unique_ptr<Solver> solver = make_solver(set, slit ? Vec3::Zero() : scene.simulation.gravity);
  run.device = solver->device();
  const std::string name = c.scene.string();

  if (slit) {
    cut_then_load(*solver, scene, set, dt);
    run.steps = relax(*solver, dt, scene.simulation.steps * 10);
    const double length = obj.shape.max.x() - obj.shape.min.x();
    run.value = mean_uz_around(set, solver->read_state(false), Vec3(length, 0, 0), name);
    run.error = std::abs(run.value / run.reference - 1);
  } else if (c.name == "cantilever_small" || c.name == "cantilever_large") {
    const size_t tip = phyxel_at(set, Vec3(0.1, 0, 0), name);
    run.steps = relax(*solver, dt, scene.simulation.steps * 10);
    const Vec3 u = solver->read_state(false).displacement[tip];
    run.value = u.z();
    run.secondary = u.x();
    run.error = std::abs(run.value / run.reference - 1);
  } else if (c.name == "uniaxial_bar") {
    run.steps = relax(*solver, dt, scene.simulation.steps * 10);
    const PointState s = solver->read_state(false);
    const double side = obj.shape.max.y() - obj.shape.min.y(), force = obj.loads.at(0).force.x(),
                 x1 = 0.03, x2 = 0.07;
    auto u = [&](const Vec3& p) { return s.displacement[phyxel_at(set, p, name)]; };
    const double axial = (u(Vec3(x2, 0, 0)) - u(Vec3(x1, 0, 0))).x() / (x2 - x1);
    const double lateral = (u(Vec3(0.05, side / 2, 0)) - u(Vec3(0.05, -side / 2, 0))).y() / side;
    run.value = force / (side * side) / axial;
    run.secondary = -lateral / axial;
    run.error = std::max(std::abs(run.value / run.reference - 1),
                         std::abs(run.secondary / obj.material.poisson - 1));
  } else if (c.name == "wave_bar") {
    // A constant pull on the free end x = L starts a step wave towards x = 0. Behind its
    // front the particles move at F / (A rho c); the time at which each station's mean
    // x-velocity crosses half of that gives the front speed between two stations.
    const Vec3 size = obj.shape.max - obj.shape.min;
    const double length = size.x(), area = size.y() * size.z();
    const double plateau = obj.loads.at(0).force.x() / (area * obj.material.density * c.reference);
    const double xa = 0.75 * length, xb = 0.25 * length, tol = 0.1 * obj.spacing;
    const std::vector<size_t> sa = layer(set, 0, xa, tol), sb = layer(set, 0, xb, tol);
    if (sa.empty() || sb.empty()) throw std::runtime_error(name + ": no station layer");
    double ta = -1, tb = -1, prev_a = 0, prev_b = 0;
    const int64_t max_steps = static_cast<int64_t>(1.2 * length / c.reference / dt) + 10;
    for (int64_t k = 1; k <= max_steps && tb < 0; ++k) {
      solver->advance(1, dt);
      const PointState s = solver->read_state(false);
      const double va = mean_x_velocity(s, sa), vb = mean_x_velocity(s, sb);
      const double half = 0.5 * std::abs(plateau);
      // Linear interpolation of the crossing between steps k-1 and k.
      if (ta < 0 && va >= half) ta = dt * (k - 1 + (half - prev_a) / (va - prev_a));
      if (tb < 0 && vb >= half) tb = dt * (k - 1 + (half - prev_b) / (vb - prev_b));
      prev_a = va;
      prev_b = vb;
      run.steps = k;
    }
    run.value = (ta > 0 && tb > ta) ? (xa - xb) / (tb - ta) : 0;
    run.error = std::abs(run.value / run.reference - 1);
  } else {
    throw std::runtime_error("unknown validation case " + c.name);
  }
  run.finite = solver->first_non_finite() < 0;
  run.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return run;
}

}  // namespace phyxel
