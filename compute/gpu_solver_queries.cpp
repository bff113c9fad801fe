// GpuSolver: what goes back to the CPU. Each query is one submit and a download:
//   energies()          per-phyxel energy pass + fixed-order GPU reduction to at most
//                       kScanBlock partial sums (16 bytes each), summed in double on the host
//   first_non_finite()  a check pass; 4 bytes back
//   read_state()        u and v (32 bytes per phyxel); von Mises from a GPU pass (4 more);
//                       the principal stress buffer (4 more, while on)
// and the test/bench helpers (forces, moment inverses, pair weights, per-pass timing).
#include <algorithm>
#include <map>
#include <stdexcept>
#include <string>

#include "compute/gpu_solver.h"
#include "compute/gpu_solver_kernels.h"

namespace phyxel::gpu {

using namespace layout;

namespace {

std::vector<Vec3> to_vec3(const std::vector<vec4>& x) {
  std::vector<Vec3> out(x.size());
  for (size_t i = 0; i < x.size(); ++i) out[i] = Vec3(x[i].x, x[i].y, x[i].z);
  return out;
}

}  // namespace

Energies GpuSolver::energies() {
  Recorder& rec = *rec_[0];
  dispatch(rec, kernels_->energy, push(count_, 0.0f),
           {nbr_offset_, nbr_index_, weight_, local_, disp_[0], vel_, ainv_, ext_, flags_, classes_,
            energy_},
           count_);
  // Reduce by kScanBlock per level until few enough partial sums are left to download.
  const Buffer* src = &energy_;
  uint32_t count = count_;
  int level = 0;
  while (count > kScanBlock) {
    const Buffer& dst = reduce_[level % 2];
    rec.barrier();
    const uint32_t groups = (count + kScanBlock - 1) / kScanBlock;
    dispatch(rec, kernels_->reduce, ReducePush{count, 0}, {*src, dst},
             groups * kernels_->reduce.workgroup_size()[0]);
    src = &dst;
    count = groups;
    ++level;
  }
  rec.submit_and_wait();
  const std::vector<vec4> partial = download<vec4>(*ctx_, *src, count);
  Energies e;
  for (const vec4& p : partial) {
    e.strain += p.x;
    e.kinetic += p.y;
    e.potential += p.z;
  }
  return e;
}

long GpuSolver::first_non_finite() {
  Recorder& rec = *rec_[0];
  rec.fill(check_, 0xffffffffu);
  rec.barrier();
  dispatch(rec, kernels_->check, CheckPush{count_, 0}, {disp_[0], vel_, check_}, count_);
  rec.submit_and_wait();
  const uint32_t first = download<uint32_t>(*ctx_, check_, 1)[0];
  return first == 0xffffffffu ? -1 : static_cast<long>(first);
}

PointState GpuSolver::read_state(bool with_stress) {
  PointState s;
  s.displacement = to_vec3(download<vec4>(*ctx_, disp_[0], count_));
  s.velocity = to_vec3(download<vec4>(*ctx_, vel_, count_));
  if (with_stress) {
    Recorder& rec = *rec_[0];
    dispatch(rec, kernels_->von_mises, push(count_, 0.0f),
             {nbr_offset_, nbr_index_, weight_, local_, disp_[0], vel_, ainv_, ext_, flags_,
              classes_, von_mises_},
             count_);
    rec.submit_and_wait();
    const std::vector<float> vm = download<float>(*ctx_, von_mises_, count_);
    s.von_mises.assign(vm.begin(), vm.end());
    if (principal_) {  // computed by the last substep's principal pass
      const std::vector<float> sigma = download<float>(*ctx_, principal_stress_, count_);
      s.max_principal_stress.assign(sigma.begin(), sigma.end());
    }
  }
  s.contact.assign(count_, 0);  // as the CPU's: 1 where a tool touched the phyxel
  if (contact_flag_) {
    const std::vector<uint32_t> flags = download<uint32_t>(*ctx_, contact_flag_, count_);
    for (size_t i = 0; i < count_; ++i) s.contact[i] = flags[i] != 0 ? 1 : 0;
  }
  return s;
}

std::vector<Vec3> GpuSolver::forces() {
  return to_vec3(download<vec4>(*ctx_, force_, count_));
}

std::vector<MomentInverseRow> GpuSolver::moment_inverses() {
  const std::vector<vec4> a = download<vec4>(*ctx_, ainv_, 2 * size_t{count_});
  const std::vector<uint32_t> flags = download<uint32_t>(*ctx_, flags_, count_);
  std::vector<MomentInverseRow> out(count_);
  for (size_t i = 0; i < count_; ++i) {
    const vec4& p = a[2 * i];
    const vec4& q = a[2 * i + 1];
    out[i] = {{p.x, p.y, p.z, p.w, q.x, q.y}, (flags[i] & kFlagRegularised) != 0};
  }
  return out;
}

std::vector<float> GpuSolver::pair_weights() {
  return download<float>(*ctx_, weight_, pairs_);
}

std::vector<PassTime> GpuSolver::profile(int64_t steps, double dt) {
  if (steps < 1) throw std::invalid_argument("GpuSolver::profile: steps must be at least 1");
  // kick_drift once; per step stress, principal while on, force, tear while on, and contact
  // and cut where there are tools.
  const int64_t per_step =
      2 + (principal_ ? 1 : 0) + (tearing_ ? 1 : 0) + (tools_.empty() ? 0 : 1) + (cutting_ ? 1 : 0);
  PassTimer timer(*ctx_, static_cast<uint32_t>(2 + per_step * steps));
  Recorder& rec = *rec_[0];
  if (!tools_.empty()) begin_contact(steps, dt);  // its uploads go first
  if (tearing_ && !cutting_) rec.fill(cut_log_, 0, 0, sizeof(uvec4));
  timer.reset(rec);
  int cur = 0;
  record_steps(rec, 0, steps, steps, static_cast<float>(dt), cur, &timer);
  rec.submit_and_wait();
  if (!tools_.empty()) finish_contact(steps, true);
  if (cutting_ || tearing_) finish_cutting();
  std::map<std::string, std::vector<double>> by_name;
  std::vector<std::string> order;
  for (const PassTime& t : timer.results()) {
    if (!by_name.count(t.name)) order.push_back(t.name);
    by_name[t.name].push_back(t.ns);
  }
  std::vector<PassTime> out;
  for (const std::string& name : order) {
    std::vector<double>& v = by_name[name];
    std::sort(v.begin(), v.end());
    out.push_back({name, v[v.size() / 2]});
  }
  return out;
}

}  // namespace phyxel::gpu
