// GpuSolver: what goes back to the CPU. Each query is one submit and a download:
//   energies()          per-phyxel energy pass + fixed-order GPU reduction to at most
//                       kScanBlock partial sums (16 bytes each), summed in double on the host
//   object_motion()     per object a fixed-order reduction of m |v|^2 / 2 and max |v| (the run
//                       loop's rest, sleep and runaway checks); 16 bytes per object back
//   first_non_finite()  a check pass; 4 bytes back
//   read_state()        u and v (32 bytes per phyxel); von Mises from a GPU pass (4 more);
//                       the principal stress buffer (4 more, while on); one submission into
//                       a persistent read-back buffer (44 bytes per phyxel, made on first use)
// and the test/bench helpers (forces, moment inverses, pair weights, per-pass timing).
#include <algorithm>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>

#include "compute/gpu_solver.h"
#include "compute/gpu_solver_kernels.h"

namespace phyxel::gpu {

using namespace layout;

namespace {

std::vector<Vec3> to_vec3(const vec4* x, size_t n) {
  std::vector<Vec3> out(n);
  for (size_t i = 0; i < n; ++i) out[i] = Vec3(x[i].x, x[i].y, x[i].z);
  return out;
}
std::vector<Vec3> to_vec3(const std::vector<vec4>& x) {
  return to_vec3(x.data(), x.size());
}

}  // namespace

void GpuSolver::record_energy_like(Recorder& rec, const Pipeline& pass, const Buffer& out) {
  dispatch(rec, pass, push(count_, 0.0f),
           {{"Offset", nbr_offset_},
            {"IndexLo", nbr_index_.lo()},
            {"WeightLo", weight_.lo()},
            {"Local", local_},
            {"Disp", disp_[0]},
            {"Vel", vel_},
            {"Ainv", ainv_},
            {"Ext", ext_},
            {"Flags", flags_},
            {"Classes", classes_},
            {"Out", out},
            {"IndexHi", nbr_index_.hi()},
            {"WeightHi", weight_.hi()}},
           count_);
}

Energies GpuSolver::energies() {
  settle();
  Recorder& rec = *rec_[0];
  record_energy_like(rec, kernels_->energy, energy_);
  // Reduce by kScanBlock per level until few enough partial sums are left to download.
  const Buffer* src = &energy_;
  uint32_t count = count_;
  int level = 0;
  while (count > kScanBlock) {
    const Buffer& dst = reduce_[level % 2];
    rec.barrier();
    const uint32_t groups = (count + kScanBlock - 1) / kScanBlock;
    dispatch(rec, kernels_->reduce, ReducePush{count, 0}, {{"Src", *src}, {"Dst", dst}},
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
  e.strain += band_energy();  // the band phyxels' (their nodal energy is 0)
  return e;
}

std::vector<ObjectMotion> GpuSolver::object_motion(const PhyxelSet& set) {
  settle();
  if (set.size() != count_)
    throw std::invalid_argument("GpuSolver::object_motion: the set has " +
                                std::to_string(set.size()) + " phyxels, the solver " +
                                std::to_string(count_));
  const size_t objects = set.objects.size();
  std::vector<ObjectMotion> out(objects);
  if (objects == 0) return out;
  if (motion_readback_.size() < objects * sizeof(vec4))
    motion_readback_ = Buffer(*ctx_, objects * sizeof(vec4), MemoryIntent::Readback,
                              "kinetic energy and largest speed per object");
  Recorder& rec = *rec_[0];
  const uint32_t threads = kernels_->motion.workgroup_size()[0];
  bool recorded = false;
  for (size_t o = 0; o < objects; ++o) {
    const ObjectRange& obj = set.objects[o];
    if (obj.count == 0) continue;
    const Buffer* src = &reduce_[1];  // not read at level 0
    uint32_t count = obj.count;
    for (uint32_t level = 0;; ++level) {
      const uint32_t groups = (count + kScanBlock - 1) / kScanBlock;
      const bool last = groups == 1;
      const Buffer& dst = last ? motion_readback_ : reduce_[level % 2];
      if (recorded) rec.barrier();  // the partials of the level (or object) before
      dispatch(rec, kernels_->motion,
               MotionPush{level == 0 ? obj.first : 0u, count, level,
                          last ? static_cast<uint32_t>(o) : 0u},
               {{"Vel", vel_}, {"Ext", ext_}, {"Src", *src}, {"Dst", dst}}, groups * threads);
      recorded = true;
      if (last) break;
      src = &dst;
      count = groups;
    }
  }
  if (!recorded) return out;
  rec.submit_and_wait();
  motion_readback_.invalidate();
  std::vector<vec4> m(objects);
  std::memcpy(m.data(), motion_readback_.mapped(), objects * sizeof(vec4));
  for (size_t o = 0; o < objects; ++o)
    if (set.objects[o].count > 0) out[o] = {double(m[o].x), double(m[o].y)};
  return out;
}

// The first phyxel with a non-finite u or v into check_ (all ones: none).
void GpuSolver::record_check(Recorder& rec) {
  rec.fill(check_, 0xffffffffu);
  rec.barrier();
  dispatch(rec, kernels_->check, CheckPush{count_, 0},
           {{"Disp", disp_[0]}, {"Vel", vel_}, {"Result", check_}}, count_);
}

// The check pass, then the max norms (what the run loop's checks read).
void GpuSolver::record_checks(Recorder& rec) {
  if (count_ == 0) return;
  rec.barrier();  // the last substep wrote u and v
  record_check(rec);
  record_max_norms(rec);
}

long GpuSolver::first_non_finite() {
  if (checks_ready_) {  // recorded at the end of the last advance, and nothing since
    settle_for_read();
  } else {
    settle();
    record_check(*rec_[0]);
    rec_[0]->submit_and_wait();
  }
  const uint32_t first = download<uint32_t>(*ctx_, check_, 1)[0];
  return first == 0xffffffffu ? -1 : static_cast<long>(first);
}

// Where read_state's fields lie in state_readback_: u and v (vec4), then von Mises, the
// principal stress and the contact flags (4 bytes each).
struct GpuSolver::StateLayout {
  VkDeviceSize vec_bytes, word_bytes, von_mises, principal, contact, total;
  explicit StateLayout(uint32_t n)
      : vec_bytes(VkDeviceSize{n} * sizeof(vec4)),
        word_bytes(VkDeviceSize{n} * sizeof(uint32_t)),
        von_mises(2 * vec_bytes),
        principal(von_mises + word_bytes),
        contact(principal + word_bytes),
        total(contact + word_bytes) {}
};

void GpuSolver::ensure_state_readback() {
  if (!state_readback_)
    state_readback_ =
        Buffer(*ctx_, StateLayout(count_).total, MemoryIntent::Readback, "state read-back");
}

void GpuSolver::record_state_copies(Recorder& rec, bool velocity, bool von_mises, bool contact) {
  const StateLayout at(count_);
  rec.copy(disp_[0], state_readback_, at.vec_bytes, 0, 0);
  if (velocity) rec.copy(vel_, state_readback_, at.vec_bytes, 0, at.vec_bytes);
  if (von_mises) rec.copy(von_mises_, state_readback_, at.word_bytes, 0, at.von_mises);
  // Computed by the last substep's stress pass, while on.
  if (principal_) rec.copy(principal_stress_, state_readback_, at.word_bytes, 0, at.principal);
  if (contact && contact_flag_)
    rec.copy(contact_flag_, state_readback_, at.word_bytes, 0, at.contact);
}

PointState GpuSolver::read_state(bool with_stress) {
  settle();
  // One submission: the von Mises pass (with stress), then copies of every field into one
  // persistent read-back buffer: u and v (vec4), von Mises, principal stress, contact flags
  // (4 bytes each). (Aspiration reads the state after every advance: five downloads, each
  // with its own staging buffer and submission, took 18 ms per read on the H100 at 20k
  // phyxels.)
  const StateLayout at(count_);
  ensure_state_readback();
  Recorder& rec = *rec_[0];
  if (with_stress) {
    record_energy_like(rec, kernels_->von_mises, von_mises_);
  }
  rec.barrier();
  record_state_copies(rec, true, with_stress, true);
  rec.submit_and_wait();
  state_readback_.invalidate();
  const char* base = static_cast<const char*>(state_readback_.mapped());
  PointState s;
  s.displacement = to_vec3(reinterpret_cast<const vec4*>(base), count_);
  s.velocity = to_vec3(reinterpret_cast<const vec4*>(base + at.vec_bytes), count_);
  if (with_stress) {
    const auto* vm = reinterpret_cast<const float*>(base + at.von_mises);
    s.von_mises.assign(vm, vm + count_);
    if (principal_) {
      const auto* sigma = reinterpret_cast<const float*>(base + at.principal);
      s.max_principal_stress.assign(sigma, sigma + count_);
    }
  }
  s.contact.assign(count_, 0);  // as the CPU's: 1 where a tool touched the phyxel
  if (contact_flag_) {
    const auto* flags = reinterpret_cast<const uint32_t*>(base + at.contact);
    for (size_t i = 0; i < count_; ++i) s.contact[i] = flags[i] != 0 ? 1 : 0;
  }
  return s;
}

std::vector<Vec3> GpuSolver::forces() {
  settle();
  return to_vec3(download<vec4>(*ctx_, force_, count_));
}

std::vector<MomentInverseRow> GpuSolver::moment_inverses() {
  settle();
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
  settle();
  return weight_.download<float>(*ctx_);
}

std::vector<PassTime> GpuSolver::profile(int64_t steps, double dt, bool per_dispatch) {
  settle();
  if (steps < 1) throw std::invalid_argument("GpuSolver::profile: steps must be at least 1");
  // kick_drift once; per step stress (with the principal stress while on), force (fused with
  // the tear test while tearing, after the dirty list's reset where it needs one), and contact
  // and cut where there are tools; per dispatch, at most 4 parts of each.
  const int64_t per_step =
      2 +
      (per_dispatch ? 4 : 1) * ((tearing_ ? 1 : 0) + (tools_.empty() ? 0 : 1) + (cutting_ ? 1 : 0));
  PassTimer timer(*ctx_, static_cast<uint32_t>(2 + per_step * steps));
  Recorder& rec = *rec_[0];
  if (!tools_.empty()) begin_contact(steps, dt);  // its uploads go first
  if (tearing_ && !cutting_) rec.fill(cut_log_, 0, 0, sizeof(uvec4));
  if (cutting_) reset_stress_beside(rec);
  timer.reset(rec);
  int cur = 0;
  if (per_dispatch) part_timer_ = &timer;
  try {
    record_steps(rec, 0, steps, steps, static_cast<float>(dt), cur, &timer);
  } catch (...) {
    part_timer_ = nullptr;
    throw;
  }
  part_timer_ = nullptr;
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
