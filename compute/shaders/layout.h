// Shared by GLSL (compute/shaders/*.comp, `#include "layout.h"`) and C++
// (`#include "compute/shaders/layout.h"`): workgroup sizes, binding numbers, and the structs
// of push constants and storage buffers. A struct written here is one definition for both
// languages, so it may use only `uint`, `int`, `float`, `vec4`, `uvec4` and `ivec4` (never a
// bare vec3: its std430 alignment differs from any C++ struct of three floats), and each one
// gets a PHYXEL_ASSERT_SIZE with its std430 size.
//
// Binding numbers are the positions in dispatch()'s buffer list, where each buffer names its
// block ({"Offset", buf} for `buffer Offset {...}`); dispatch() checks the names against the
// SPIR-V.
#ifndef PHYXEL_COMPUTE_SHADERS_LAYOUT_H
#define PHYXEL_COMPUTE_SHADERS_LAYOUT_H

#ifdef __cplusplus
#include <cstdint>
namespace phyxel::gpu::layout {
using uint = std::uint32_t;
struct alignas(16) vec4 {
  float x, y, z, w;
};
struct alignas(16) uvec4 {
  uint x, y, z, w;
};
struct alignas(16) ivec4 {
  int x, y, z, w;
};
#define PHYXEL_CONST inline constexpr
#define PHYXEL_ASSERT_SIZE(T, bytes) \
  static_assert(sizeof(T) == (bytes), #T " must match its std430 size in GLSL")
#else
#define PHYXEL_CONST const
// In GLSL the size becomes a constant, <T>_kStd430Size.
#define PHYXEL_ASSERT_SIZE(T, bytes) const uint T##_kStd430Size = bytes
#endif

// Threads per workgroup of the 1D kernels (a multiple of every subgroup size in use; never
// assume the subgroup size itself: lavapipe's is 8, NVIDIA's 32, AMD's 32 or 64).
#define PHYXEL_WORKGROUP_SIZE 64

PHYXEL_ASSERT_SIZE(vec4, 16);
PHYXEL_ASSERT_SIZE(uvec4, 16);
PHYXEL_ASSERT_SIZE(ivec4, 16);

// iota.comp: dst[i] = base + i for i < count (writes its global index; proves dispatch).
PHYXEL_CONST uint kIotaBindingDst = 0;
struct IotaPush {
  uint count;
  uint base;
};
PHYXEL_ASSERT_SIZE(IotaPush, 8);

// axpy.comp: y[i] = a * x[i] + y[i] for i < count.
PHYXEL_CONST uint kAxpyBindingX = 0;
PHYXEL_CONST uint kAxpyBindingY = 1;
struct AxpyPush {
  float a;
  uint count;
};
PHYXEL_ASSERT_SIZE(AxpyPush, 8);

// stream_copy.comp: dst[i] = src[i] over `count` uvec4, `per_thread` of them per invocation,
// `threads` apart (each warp's loads and stores contiguous): the streaming bandwidth that
// measure_copy_bandwidth reports as the roofline (compute/timing.h).
PHYXEL_CONST uint kStreamCopyBindingSrc = 0;
PHYXEL_CONST uint kStreamCopyBindingDst = 1;
struct StreamCopyPush {
  uint count;
  uint per_thread;
  uint threads;
  uint pad;
};
PHYXEL_ASSERT_SIZE(StreamCopyPush, 16);

// ---------------------------------------------------------------------------------------
// GPU solver (compute/gpu_solver*.cpp, shaders/nbr_*.comp, scan_*.comp, solver_*.comp).
// Per-phyxel buffers are arrays of vec4 (or uint/float), indexed by phyxel; per-pair buffers
// are aligned with the CSR neighbour index (see compute/README.md, "GPU solver buffers"), and
// each shader binds both of their parts, lo and hi (PairBuffer, pair_buffers.glsl): the *IndexHi
// and *WeightHi bindings come last in every list.

// The engine's PhyxelFlags (engine/sampling/phyxel_set.h) in the low byte of the per-phyxel flags
// word, the GPU's own status bits above them, and the phyxel's parameter class in the high 16 bits.
PHYXEL_CONST uint kFlagFixed = 1u;
PHYXEL_CONST uint kFlagSurface = 2u;
PHYXEL_CONST uint kFlagRemoved = 4u;
PHYXEL_CONST uint kFlagRegularised = 256u;  // set by solver_precompute: A_i was regularised
// Some of the phyxel's pairs were deactivated (weight 0 in the pair-weight buffer): the passes
// read its stored weights instead of recomputing them from x0 (see kWeightsAuto).
PHYXEL_CONST uint kFlagPairsEdited = 512u;
// In the current substep's cut list (tool_sever); solver_precompute's cut mode clears it.
PHYXEL_CONST uint kFlagCutDirty = 1024u;
PHYXEL_CONST uint kFlagClassShift = 16u;  // flags >> 16 = index into the SolverClass array
PHYXEL_CONST uint kMaxSolverClasses = 65536u;

// One (object, material) combination: what the passes need besides per-phyxel data.
struct SolverClass {
  vec4 elastic;  // lambda' = lambda - k_v, mu, k_v, mass-proportional damping c (1/s)
  vec4 kernel;   // h^2, 315 / (64 pi h^3) (poly6 = that (1 - r^2/h^2)^3), hourglass gamma,
                 // hash cell size
  vec4 search;   // h^2 (1 - 1e-9) as hi + lo (two floats, for the double test);
                 // h^2 (1 - 1e-5) (the float test); the material's tear_stress (Pa, 0: none)
  uvec4 ids;     // object index, material index, 0, 0
};
PHYXEL_ASSERT_SIZE(SolverClass, 64);

// Neighbour search (nbr_cells, nbr_scatter, nbr_pairs). Buckets of the spatial hash: a power
// of two; cell = floor(x_local / cell size) per axis, hashed with the object index.
struct NbrPush {
  uint end;          // phyxels [first, end) (the setup runs in chunks of phyxels)
  uint bucket_mask;  // buckets - 1
  uint mode;         // nbr_pairs: kNbrCount or kNbrFill
  uint first;
};
PHYXEL_ASSERT_SIZE(NbrPush, 16);
PHYXEL_CONST uint kNbrCount = 0u;
PHYXEL_CONST uint kNbrFill = 1u;

// nbr_cells: buffers {local, flags, classes, cell_of, slot, bucket_count}
PHYXEL_CONST uint kNbrCellsBindingLocal = 0;
PHYXEL_CONST uint kNbrCellsBindingFlags = 1;
PHYXEL_CONST uint kNbrCellsBindingClasses = 2;
PHYXEL_CONST uint kNbrCellsBindingCellOf = 3;
PHYXEL_CONST uint kNbrCellsBindingSlot = 4;
PHYXEL_CONST uint kNbrCellsBindingBucketCount = 5;
// nbr_scatter: buffers {cell_of, slot, bucket_start, sorted}
PHYXEL_CONST uint kNbrScatterBindingCellOf = 0;
PHYXEL_CONST uint kNbrScatterBindingSlot = 1;
PHYXEL_CONST uint kNbrScatterBindingBucketStart = 2;
PHYXEL_CONST uint kNbrScatterBindingSorted = 3;
// nbr_pairs: buffers {local, rest_lo, flags, classes, cell_of, bucket_start, sorted, count,
// offset, index, weight}; kNbrCount writes count[i], kNbrFill writes the sorted row i of index
// (from offset[i]) and its poly6 weights.
PHYXEL_CONST uint kNbrPairsBindingLocal = 0;
PHYXEL_CONST uint kNbrPairsBindingRestLo = 1;
PHYXEL_CONST uint kNbrPairsBindingFlags = 2;
PHYXEL_CONST uint kNbrPairsBindingClasses = 3;
PHYXEL_CONST uint kNbrPairsBindingCellOf = 4;
PHYXEL_CONST uint kNbrPairsBindingBucketStart = 5;
PHYXEL_CONST uint kNbrPairsBindingSorted = 6;
PHYXEL_CONST uint kNbrPairsBindingCount = 7;
PHYXEL_CONST uint kNbrPairsBindingOffset = 8;
PHYXEL_CONST uint kNbrPairsBindingIndex = 9;
PHYXEL_CONST uint kNbrPairsBindingWeight = 10;
PHYXEL_CONST uint kNbrPairsBindingIndexHi = 11;  // pairs past the first binding (pair_buffers.glsl)
PHYXEL_CONST uint kNbrPairsBindingWeightHi = 12;

// Exclusive prefix sum in blocks of kScanBlock elements (scan_block then scan_add per level):
// out[i] = sum of in[k] for k < i, i < count, where in[k] = 0 for k >= input_count.
#define PHYXEL_SCAN_PER_THREAD 4
PHYXEL_CONST uint kScanBlock = PHYXEL_WORKGROUP_SIZE * PHYXEL_SCAN_PER_THREAD;
struct ScanPush {
  uint count;
  uint input_count;
};
PHYXEL_ASSERT_SIZE(ScanPush, 8);
PHYXEL_CONST uint kScanBindingIn = 0;  // scan_block: {in, out, block_sums}
PHYXEL_CONST uint kScanBindingOut = 1;
PHYXEL_CONST uint kScanBindingSums = 2;
PHYXEL_CONST uint kScanAddBindingOut = 0;  // scan_add: {out, scanned block sums}
PHYXEL_CONST uint kScanAddBindingSums = 1;

// solver_precompute: buffers {offset, index, weight, local, flags, classes, rest, ainv, resid}.
// Per phyxel (all, or those listed when `indexed`): A_i from the stored pair weights, its
// regularised inverse (2 vec4: a00 a01 a02 a11 | a12 a22 volume 0), the residual
// A^-1 A A^-1 - A^-1 (same packing, zero unless regularised), kappa_i into local.w and the
// kFlagRegularised bit. Idempotent: after pairs are deactivated (weight 0) it recomputes the
// phyxels they touch.
struct PrecomputePush {
  uint count;
  uint indexed;  // 1: phyxel = list[invocation]; 0: phyxel = first + invocation;
                 // kPrecomputeCutList: the count and phyxels of a CutDirty list (list[0],
                 // list[4 + invocation]), dispatched indirectly from list[1..3], clearing
                 // kFlagCutDirty
  uint first;    // indexed 0: the phyxel of invocation 0 (the setup runs in chunks)
  uint pad;
};
PHYXEL_CONST uint kPrecomputeCutList = 2u;
PHYXEL_ASSERT_SIZE(PrecomputePush, 16);
PHYXEL_CONST uint kPrecomputeBindingOffset = 0;
PHYXEL_CONST uint kPrecomputeBindingIndex = 1;
PHYXEL_CONST uint kPrecomputeBindingWeight = 2;
PHYXEL_CONST uint kPrecomputeBindingLocal = 3;
PHYXEL_CONST uint kPrecomputeBindingFlags = 4;
PHYXEL_CONST uint kPrecomputeBindingClasses = 5;
PHYXEL_CONST uint kPrecomputeBindingRest = 6;
PHYXEL_CONST uint kPrecomputeBindingAinv = 7;
PHYXEL_CONST uint kPrecomputeBindingResid = 8;
PHYXEL_CONST uint kPrecomputeBindingList = 9;
PHYXEL_CONST uint kPrecomputeBindingIndexHi = 10;
PHYXEL_CONST uint kPrecomputeBindingWeightHi = 11;

// The step passes. dt in seconds; `weights` selects where w_ij comes from. solver_kick_drift,
// solver_stress and solver_force visit the phyxels of a pass list (binding kKickDriftBindingList
// etc.: uint phyxel indices, ascending, built on the host by GpuSolver::build_pass_lists) and
// `count` is its length; solver_energy and solver_von_mises visit every phyxel (count = N).
struct StepPush {
  uint count;
  float dt;
  uint mode;     // solver_force: kForceOnly, kForceKick or kForceKickDrift
  uint weights;  // kWeightsStored or kWeightsAuto
  // Invocations per phyxel of the gathering passes (stress, force, principal): a power of two
  // up to kMaxLanes; each walks every lanes-th neighbour and lane 0 adds the partial sums in
  // lane order. The dispatch has count * lanes invocations. Other passes ignore it.
  uint lanes;
};
PHYXEL_ASSERT_SIZE(StepPush, 20);
PHYXEL_CONST uint kMaxLanes = 16u;
PHYXEL_CONST uint kForceOnly = 0u;       // f = ext + internal
PHYXEL_CONST uint kForceKick = 1u;       // ... then the closing half kick of this step
PHYXEL_CONST uint kForceKickDrift = 2u;  // ... then the next step's half kick and drift
// kWeightsStored: every w_ij from the pair-weight buffer. kWeightsAuto: recomputed as poly6 of
// x0 (the same float expression that filled the buffer, so the same value) except for phyxels
// flagged kFlagPairsEdited, which read the buffer. Reading 4 bytes per pair with one row per
// thread costs far more than the bytes (the rows of a warp stride through L1): 3.6x per step
// at 1M phyxels on an H100 (docs/performance.md).
PHYXEL_CONST uint kWeightsStored = 0u;
PHYXEL_CONST uint kWeightsAuto = 1u;

// solver_kick_drift: {disp_in, disp_out, vel, force, ext, flags, classes, list}
PHYXEL_CONST uint kKickDriftBindingDispIn = 0;
PHYXEL_CONST uint kKickDriftBindingDispOut = 1;
PHYXEL_CONST uint kKickDriftBindingVel = 2;
PHYXEL_CONST uint kKickDriftBindingForce = 3;
PHYXEL_CONST uint kKickDriftBindingExt = 4;
PHYXEL_CONST uint kKickDriftBindingFlags = 5;
PHYXEL_CONST uint kKickDriftBindingClasses = 6;
PHYXEL_CONST uint kKickDriftBindingList = 7;  // the force pass list
// solver_stress: {offset, index, weight, local, disp, ainv, resid, flags, classes, stress, list}
// stress = D_i as 3 vec4 columns (xyz; w unused).
PHYXEL_CONST uint kStressBindingOffset = 0;
PHYXEL_CONST uint kStressBindingIndex = 1;
PHYXEL_CONST uint kStressBindingWeight = 2;
PHYXEL_CONST uint kStressBindingLocal = 3;
PHYXEL_CONST uint kStressBindingDisp = 4;
PHYXEL_CONST uint kStressBindingAinv = 5;
PHYXEL_CONST uint kStressBindingResid = 6;
PHYXEL_CONST uint kStressBindingFlags = 7;
PHYXEL_CONST uint kStressBindingClasses = 8;
PHYXEL_CONST uint kStressBindingStress = 9;
PHYXEL_CONST uint kStressBindingList = 10;  // the stress pass list
PHYXEL_CONST uint kStressBindingIndexHi = 11;
PHYXEL_CONST uint kStressBindingWeightHi = 12;
// solver_force: {offset, index, weight, local, disp_in, disp_out, stress, vel, force, ext, flags,
// classes, list}
PHYXEL_CONST uint kForceBindingOffset = 0;
PHYXEL_CONST uint kForceBindingIndex = 1;
PHYXEL_CONST uint kForceBindingWeight = 2;
PHYXEL_CONST uint kForceBindingLocal = 3;
PHYXEL_CONST uint kForceBindingDispIn = 4;
PHYXEL_CONST uint kForceBindingDispOut = 5;
PHYXEL_CONST uint kForceBindingStress = 6;
PHYXEL_CONST uint kForceBindingVel = 7;
PHYXEL_CONST uint kForceBindingForce = 8;
PHYXEL_CONST uint kForceBindingExt = 9;
PHYXEL_CONST uint kForceBindingFlags = 10;
PHYXEL_CONST uint kForceBindingClasses = 11;
PHYXEL_CONST uint kForceBindingList = 12;  // the force pass list
PHYXEL_CONST uint kForceBindingIndexHi = 13;
PHYXEL_CONST uint kForceBindingWeightHi = 14;

// solver_energy: {offset, index, weight, local, disp, vel, ainv, ext, flags, classes, out}
// out[i] = (strain, kinetic, potential, 0) of phyxel i; solver_von_mises: the same inputs but
// vel and ext unused (bound anyway), out = float von Mises stress per phyxel.
PHYXEL_CONST uint kEnergyBindingOffset = 0;
PHYXEL_CONST uint kEnergyBindingIndex = 1;
PHYXEL_CONST uint kEnergyBindingWeight = 2;
PHYXEL_CONST uint kEnergyBindingLocal = 3;
PHYXEL_CONST uint kEnergyBindingDisp = 4;
PHYXEL_CONST uint kEnergyBindingVel = 5;
PHYXEL_CONST uint kEnergyBindingAinv = 6;
PHYXEL_CONST uint kEnergyBindingExt = 7;
PHYXEL_CONST uint kEnergyBindingFlags = 8;
PHYXEL_CONST uint kEnergyBindingClasses = 9;
PHYXEL_CONST uint kEnergyBindingOut = 10;
PHYXEL_CONST uint kEnergyBindingIndexHi = 11;
PHYXEL_CONST uint kEnergyBindingWeightHi = 12;

// solver_principal (tearing; only while GpuSolver::set_principal_stress is on), over the stress
// pass list with StepPush (dt unused): out[i] = the largest principal value of the Cauchy
// stress of phyxel i (float, Pa), for the u in disp; with mode kPrincipalWithTensor (tearing on)
// also the symmetrised tensor into cauchy[2 i] = (xx, yy, zz, xy), cauchy[2 i + 1] = (xz, yz,
// 0, 0). {offset, index, weight, local, disp, ainv, flags, classes, out, list, cauchy}
PHYXEL_CONST uint kPrincipalBindingOffset = 0;
PHYXEL_CONST uint kPrincipalBindingIndex = 1;
PHYXEL_CONST uint kPrincipalBindingWeight = 2;
PHYXEL_CONST uint kPrincipalBindingLocal = 3;
PHYXEL_CONST uint kPrincipalBindingDisp = 4;
PHYXEL_CONST uint kPrincipalBindingAinv = 5;
PHYXEL_CONST uint kPrincipalBindingFlags = 6;
PHYXEL_CONST uint kPrincipalBindingClasses = 7;
PHYXEL_CONST uint kPrincipalBindingOut = 8;
PHYXEL_CONST uint kPrincipalBindingList = 9;  // the stress pass list
// vec4[2 N]; without tearing the principal buffer is bound here and never written.
PHYXEL_CONST uint kPrincipalBindingCauchy = 10;
PHYXEL_CONST uint kPrincipalBindingIndexHi = 11;
PHYXEL_CONST uint kPrincipalBindingWeightHi = 12;
PHYXEL_CONST uint kPrincipalWithTensor = 1u;  // StepPush.mode

// solver_tear (engine/solver/tearing.h), over the stress pass list after the force pass of a
// substep, on the u the stress pass read: each phyxel tests its live pairs to higher indices
// (each pair has one owner: no atomics on the weights); a pair whose mean normal stress
// reaches the mean of the two classes' tear_stress gets weight 0 in both slots, is logged as
// (i, j, 0.5 bits, 1) in the cut log and puts both phyxels in the dirty list (tool_sever's).
struct TearPush {
  uint count;  // stress pass list length
  uint log_capacity;
  uint pad0, pad1;
};
PHYXEL_ASSERT_SIZE(TearPush, 16);
PHYXEL_CONST uint kTearBindingList = 0;  // the stress pass list
PHYXEL_CONST uint kTearBindingRest = 1;
PHYXEL_CONST uint kTearBindingDisp = 2;
PHYXEL_CONST uint kTearBindingOffset = 3;
PHYXEL_CONST uint kTearBindingIndex = 4;
PHYXEL_CONST uint kTearBindingWeight = 5;  // the pair weights, as uint bits
PHYXEL_CONST uint kTearBindingFlags = 6;
PHYXEL_CONST uint kTearBindingClasses = 7;
PHYXEL_CONST uint kTearBindingPrincipal = 8;  // float per phyxel (solver_principal)
PHYXEL_CONST uint kTearBindingCauchy = 9;     // vec4[2 N] (solver_principal)
PHYXEL_CONST uint kTearBindingDirty = 10;     // tool_sever's dirty list
PHYXEL_CONST uint kTearBindingLog = 11;       // the cut log
PHYXEL_CONST uint kTearBindingIndexHi = 12;
PHYXEL_CONST uint kTearBindingWeightHi = 13;

// solver_reduce: out[g] = sum of in[g * kScanBlock .. + kScanBlock) (vec4), in a fixed order.
PHYXEL_CONST uint kReduceBindingIn = 0;
PHYXEL_CONST uint kReduceBindingOut = 1;
struct ReducePush {
  uint count;  // input elements
  uint pad;
};
PHYXEL_ASSERT_SIZE(ReducePush, 8);

// solver_check: result[0] = min(result[0], i) for every phyxel with a non-finite u or v.
PHYXEL_CONST uint kCheckBindingDisp = 0;
PHYXEL_CONST uint kCheckBindingVel = 1;
PHYXEL_CONST uint kCheckBindingResult = 2;
struct CheckPush {
  uint count;
  uint pad;
};
PHYXEL_ASSERT_SIZE(CheckPush, 8);

// ---------------------------------------------------------------------------------------
// Tool contact (compute/gpu_solver_contact.cpp; shaders/tool_contact*.comp, solver_max_norm.comp;
// the math in shaders/tool_contact.glsl mirrors engine/geometry/tool.cpp and
// engine/solver/contact.cpp).

// A tool's shape and friction (engine ContactTool), one per tool.
PHYXEL_CONST uint kToolSphere = 0u;
PHYXEL_CONST uint kToolCapsule = 1u;
struct ContactToolShape {
  vec4 shape;    // radius (m), length (m; 0 for a sphere), Coulomb friction mu, and for a blade
                 // the band around it whose phyxels span its axial range (m; 0: contacts only)
  uvec4 kind;    // kToolSphere or kToolCapsule, 0, 0, 0
  vec4 suction;  // an aspirator's pull per unit volume in reach 2 F / V_reach (N/m^3; 0: none),
                 // its reach (m), its flow speed (m/s), 0 (engine/solver/suction.h)
};
PHYXEL_ASSERT_SIZE(ContactToolShape, 48);
// The axial range a (candidate, tool) without contact contributes (engine ToolContactSample).
PHYXEL_CONST float kNoContactAxial = 1e30;

// One substep's motion of one tool (engine ToolMotion), row-major [substep][tool]. Positions
// are relative to ContactPush.origin (a point near the tools, so the small per-substep motion
// keeps its precision in float); axes are unit vectors (w unused).
struct ContactMotion {
  vec4 from_position;
  vec4 from_axis;
  vec4 to_position;  // w: 1 where an aspirator sucks in the substep (ToolMotion::suction_on)
  vec4 to_axis;
};
PHYXEL_ASSERT_SIZE(ContactMotion, 64);

// tool_contact: over the candidate list, after a drift: the correction of every tool in turn
// (u += dx, v += dv on the displacement buffer that holds the new u), the contact forces
// m dv / dt of each workgroup's candidates summed per tool into force[tool * capacity + group]
// (xyz; w: the contacts) and their axial range into force[(tools + tool) * capacity + group],
// and the per-phyxel contact flag (1 touched, 0 not).
struct ContactPush {
  vec4 origin;    // xyz: the frame of the motion table (world, m), w unused
  uint unused;    // (the candidates are counted on the GPU: ContactCount.total)
  float dt;       // s
  uint tools;     // tools
  uint motion;    // row of the motion table (substep of the chunk, clamped to its last)
  uint hold;      // 1 past the chunk's motions: the tools stay at the row's end pose
  uint capacity;  // stride of the per-workgroup force buffer (>= its workgroups)
  uint pad0;
  uint pad1;
};
PHYXEL_ASSERT_SIZE(ContactPush, 48);
// tool_contact: {list, rest, disp, vel, ext, flags, tools, motion, force, contact}
PHYXEL_CONST uint kContactBindingList = 0;  // candidate phyxels, ascending
PHYXEL_CONST uint kContactBindingRest = 1;
PHYXEL_CONST uint kContactBindingDisp = 2;
PHYXEL_CONST uint kContactBindingVel = 3;
PHYXEL_CONST uint kContactBindingExt = 4;
PHYXEL_CONST uint kContactBindingFlags = 5;
PHYXEL_CONST uint kContactBindingTools = 6;
PHYXEL_CONST uint kContactBindingMotion = 7;
PHYXEL_CONST uint kContactBindingForce = 8;
PHYXEL_CONST uint kContactBindingContact = 9;
PHYXEL_CONST uint kContactBindingCount = 10;  // ContactCount (tool_broad_scan)

// tool_contact_reduce: one workgroup per tool sums force[tool * capacity + k] over
// tool_contact's workgroups k, in a fixed order (thread t takes k = t, t + workgroup, ...; then a
// fixed tree) and writes samples[sample * tools + tool] = (minus the summed force: the force on the
// tool, contacts).
struct ContactReducePush {
  uint unused;  // (ContactCount.total)
  uint tools;
  uint capacity;
  uint substep;  // of the advance: the row of the samples
};
PHYXEL_ASSERT_SIZE(ContactReducePush, 16);
PHYXEL_CONST uint kContactReduceBindingForce = 0;
PHYXEL_CONST uint kContactReduceBindingSamples = 1;
PHYXEL_CONST uint kContactReduceBindingCount = 2;

// The broad phase of a chunk, on the GPU (CpuSolver::set_tool_motion is its twin): the entries
// of the force list (moving phyxels of awake objects) that are not fixed or removed and whose
// current position rest + u lies inside the tools' swept bounds grown by the margin
// 2 duration max(max|v|, tool speed) + spacing (contact_margin in engine/solver/contact.h;
// max|v| from the solver_max_norm reduction). tool_broad_phase runs twice over the list: mode 0
// counts each workgroup's hits into group[g]; tool_broad_scan turns the counts into exclusive
// offsets (one workgroup), the total and the indirect dispatch of tool_contact; mode 1 writes the
// hits at their offsets, in list order, so the candidates are ascending and the same on every run.
struct BroadPhasePush {
  vec4 lo;           // xyz: swept bounds min (world, m); w: spacing (m)
  vec4 hi;           // xyz: swept bounds max (world, m); w: chunk duration (s)
  uint count;        // entries of the force list
  uint mode;         // 0: count per workgroup; 1: write
  uint groups;       // workgroups of tool_broad_phase (entries of group[])
  float tool_speed;  // m/s: the fastest point of a tool over the chunk (contact_margin)
};
PHYXEL_ASSERT_SIZE(BroadPhasePush, 48);
PHYXEL_CONST uint kBroadBindingList = 0;  // force list
PHYXEL_CONST uint kBroadBindingRest = 1;
PHYXEL_CONST uint kBroadBindingDisp = 2;
PHYXEL_CONST uint kBroadBindingFlags = 3;
PHYXEL_CONST uint kBroadBindingMaxNorm = 4;  // vec4 (max |u|, max |v|, 0, 0)
PHYXEL_CONST uint kBroadBindingGroup = 5;    // uint per workgroup: hits (mode 0), offset (1)
PHYXEL_CONST uint kBroadBindingOut = 6;      // candidate list
// tool_broad_scan: {group, count}
PHYXEL_CONST uint kBroadScanBindingGroup = 0;
PHYXEL_CONST uint kBroadScanBindingCount = 1;
// solver_edit (GpuSolver::remove_phyxels): mode 0 ORs edits[2k + 1] into flags[edits[2k]] for
// k < count and zeroes the pair weight of slots[k] for k < slots; mode 1 (after
// solver_precompute) counts over every phyxel those flagged kFlagRegularised and
// kFlagPairsEdited into counts[0] and counts[1] (a fixed tree per workgroup, then one atomic
// add each), as GpuSolver::count_flags does on the host.
struct EditPush {
  uint count;  // flag edits (mode 0), phyxels (mode 1)
  uint slots;  // pair slots to zero (mode 0)
  uint mode;   // 0, 1 (above)
  uint unused;
};
PHYXEL_ASSERT_SIZE(EditPush, 16);
PHYXEL_CONST uint kEditBindingFlags = 0;
PHYXEL_CONST uint kEditBindingEdits = 1;   // uint pairs (phyxel, flag bits)
PHYXEL_CONST uint kEditBindingSlots = 2;   // uint pair slot
PHYXEL_CONST uint kEditBindingCounts = 3;  // uint[2], zeroed before mode 1
PHYXEL_CONST uint kEditBindingIndex = 4;
PHYXEL_CONST uint kEditBindingIndexHi = 5;
PHYXEL_CONST uint kEditBindingWeight = 6;
PHYXEL_CONST uint kEditBindingWeightHi = 7;

// solver_near (aspiration's reads, engine/surgery/aspiration.h): mode 0 counts, per workgroup of
// phyxels, those whose current position rest + u lies in [lo, hi]; tool_broad_scan (given a
// BroadPhasePush with the same groups) turns the counts into offsets and the total; mode 1
// writes each hit's index and (u, largest principal stress) at its offset, ascending; mode 2
// writes (u, principal) of ids[k] for k < count (a gather by index).
struct NearPush {
  vec4 lo;         // xyz: box min (world, m)
  vec4 hi;         // xyz: box max (world, m)
  uint count;      // phyxels (modes 0, 1), ids (mode 2)
  uint mode;       // 0, 1, 2 (above)
  uint groups;     // workgroups of modes 0 and 1 (entries of group[])
  uint principal;  // 1: the principal stress buffer is bound and on; 0: write 0
};
PHYXEL_ASSERT_SIZE(NearPush, 48);
PHYXEL_CONST uint kNearBindingRest = 0;
PHYXEL_CONST uint kNearBindingDisp = 1;
PHYXEL_CONST uint kNearBindingPrincipal = 2;  // float per phyxel
PHYXEL_CONST uint kNearBindingGroup = 3;      // uint per workgroup: hits (mode 0), offset (1)
PHYXEL_CONST uint kNearBindingIds = 4;        // out (mode 1), in (mode 2)
PHYXEL_CONST uint kNearBindingOut = 5;        // vec4 (u, principal) per id
// The candidate count and tool_contact's indirect dispatch (x, y, z groups), after the scan.
struct ContactCount {
  uint total;
  uint groups_x;
  uint groups_y;
  uint groups_z;
};
PHYXEL_ASSERT_SIZE(ContactCount, 16);

// ---------------------------------------------------------------------------------------
// Graspers (compute/gpu_solver_grasp.cpp; shaders/tool_grasp.comp mirrors
// engine/solver/cpu_solver_grasp.cpp and engine/solver/grasper.h).

// A held phyxel: its offset from the tip in the tool's frame (m; grip_offset), and its index.
// Per grasper a region of `capacity` entries of the grip buffer.
struct GraspEntry {
  vec4 offset;   // xyz offset, w unused
  uvec4 phyxel;  // x: the phyxel, y z w unused
};
PHYXEL_ASSERT_SIZE(GraspEntry, 32);

// tool_grasp, one pipeline with three modes, after tool_contact_reduce in a substep whose
// motion closes the tool's jaws:
//   kGraspCapture  one workgroup: the candidates (ascending) that are neither fixed nor
//                  removed and lie within reach of the tip at the end pose, appended in order
//                  with their offsets to the tool's grip; its ContactCount (total, indirect
//                  dispatch) written (only in the substep the jaws close)
//   kGraspHold     over the tool's grip (indirect): each held phyxel that is not removed put
//                  where the tool carries its offset, with the tool's velocity there; its
//                  force m dv / dt and 1 into force[tool * capacity + entry] (0 for a removed
//                  one)
//   kGraspReduce   one workgroup: the forces summed in a fixed order (tool_contact_reduce's),
//                  subtracted from the tool's sample of the substep, and the held count into
//                  its second row's z
PHYXEL_CONST uint kGraspCapture = 0u;
PHYXEL_CONST uint kGraspHold = 1u;
PHYXEL_CONST uint kGraspReduce = 2u;
struct GraspPush {
  vec4 origin;  // the motion table's frame (ContactPush.origin); w: the reach (m)
  float dt;     // s
  uint tool;
  uint tools;
  uint motion;    // row of the motion table (ContactPush.motion)
  uint hold;      // 1 past the chunk's motions (ContactPush.hold)
  uint capacity;  // entries per tool of the grip and force buffers (the phyxel count)
  uint mode;      // kGrasp*
  uint substep;   // of the advance: the row of the samples
};
PHYXEL_ASSERT_SIZE(GraspPush, 48);
PHYXEL_CONST uint kGraspBindingList = 0;        // contact candidates, ascending
PHYXEL_CONST uint kGraspBindingCandidates = 1;  // their ContactCount
PHYXEL_CONST uint kGraspBindingRest = 2;
PHYXEL_CONST uint kGraspBindingDisp = 3;
PHYXEL_CONST uint kGraspBindingVel = 4;
PHYXEL_CONST uint kGraspBindingExt = 5;
PHYXEL_CONST uint kGraspBindingFlags = 6;
PHYXEL_CONST uint kGraspBindingMotion = 7;
PHYXEL_CONST uint kGraspBindingGrip = 8;    // GraspEntry [tool][capacity]
PHYXEL_CONST uint kGraspBindingCount = 9;   // ContactCount per tool: the grip's
PHYXEL_CONST uint kGraspBindingForce = 10;  // vec4 [tool][capacity]
PHYXEL_CONST uint kGraspBindingSamples = 11;

// ---------------------------------------------------------------------------------------
// Cutting (compute/gpu_solver_cutting.cpp; shaders/tool_sever.comp mirrors
// engine/solver/cpu_solver_cutting.cpp and engine/solver/cutting.cpp).

// The quad one tool's blade swept in one substep (engine swept_quad), relative to the contact
// origin, row-major [row][tool]; rows are the chunk's substeps then one for holding the last
// pose. edge.w: the cut force threshold (N), negative for a tool without a blade. axis and
// resist: the edge's resistance (engine EdgeFrame; the tip is p3 + p3.w edge, the body's
// radius p0.w): the axis at the end pose (w: the blade's length, m) and (stiffness N/m^3, 0 where
// nothing is held; depth m; the tip's and the end's motion along the edge, m).
struct CutQuad {
  vec4 p0;
  vec4 p1;
  vec4 p2;
  vec4 p3;
  vec4 edge;
  vec4 axis;
  vec4 resist;
};
PHYXEL_ASSERT_SIZE(CutQuad, 112);

// tool_sever: over the candidates, after tool_contact_reduce: for every tool whose sample of
// this substep presses its edge with at least its threshold, each candidate tests its live
// pairs (canonical order, lower index first) against the tool's quad. The pair's slot in the
// lower index's row is claimed by an atomic exchange (so each pair is severed and logged once);
// the winner zeroes both slots, logs (i, j, t) and puts both phyxels in the dirty list (once
// each, by kFlagCutDirty), growing its indirect dispatch.
struct SeverPush {
  vec4 origin;  // the motion table's frame (ContactPush.origin)
  uint tools;
  uint row;         // row of the cut table
  uint sample_row;  // substep of the advance (its sample is rows 2 (substep tools + tool), +1)
  uint log_capacity;
};
PHYXEL_ASSERT_SIZE(SeverPush, 32);
PHYXEL_CONST uint kSeverBindingList = 0;  // candidates
PHYXEL_CONST uint kSeverBindingRest = 1;
PHYXEL_CONST uint kSeverBindingDisp = 2;
PHYXEL_CONST uint kSeverBindingOffset = 3;
PHYXEL_CONST uint kSeverBindingIndex = 4;
PHYXEL_CONST uint kSeverBindingWeight = 5;  // the pair weights, as uint bits
PHYXEL_CONST uint kSeverBindingFlags = 6;
PHYXEL_CONST uint kSeverBindingQuads = 7;    // CutQuad [row][tool]
PHYXEL_CONST uint kSeverBindingSamples = 8;  // vec4 [substep][tool]: force on the tool
PHYXEL_CONST uint kSeverBindingDirty = 9;    // uint: count, groups x y z, then phyxels
PHYXEL_CONST uint kSeverBindingLog = 10;     // uvec4: (count, 0, 0, 0), then (i, j, t bits, torn)
PHYXEL_CONST uint kSeverBindingCount = 11;   // ContactCount
PHYXEL_CONST uint kSeverBindingIndexHi = 12;
PHYXEL_CONST uint kSeverBindingWeightHi = 13;

// tool_resist: over the candidates, after tool_contact and before tool_contact_reduce (the
// CPU twin is CpuSolver::apply_edge_resistance): each candidate that is neither fixed nor
// removed sums the forces of the pairs each blade's edge holds (canonical order, its share),
// adds dt / m times them to its velocity, and each workgroup adds its candidates' sums per tool
// to tool_contact's partial force[tool * capacity + group].
struct ResistPush {
  vec4 origin;  // the motion table's frame (ContactPush.origin)
  float dt;     // s
  uint tools;
  uint row;       // row of the cut table (SeverPush.row)
  uint capacity;  // stride of the partial force buffer (ContactPush.capacity)
};
PHYXEL_ASSERT_SIZE(ResistPush, 32);
PHYXEL_CONST uint kResistBindingList = 0;  // candidates
PHYXEL_CONST uint kResistBindingRest = 1;
PHYXEL_CONST uint kResistBindingDisp = 2;
PHYXEL_CONST uint kResistBindingVel = 3;
PHYXEL_CONST uint kResistBindingExt = 4;
PHYXEL_CONST uint kResistBindingFlags = 5;
PHYXEL_CONST uint kResistBindingOffset = 6;
PHYXEL_CONST uint kResistBindingIndex = 7;
PHYXEL_CONST uint kResistBindingWeight = 8;
PHYXEL_CONST uint kResistBindingQuads = 9;   // CutQuad [row][tool]
PHYXEL_CONST uint kResistBindingForce = 10;  // tool_contact's partials
PHYXEL_CONST uint kResistBindingCount = 11;  // ContactCount
PHYXEL_CONST uint kResistBindingIndexHi = 12;
PHYXEL_CONST uint kResistBindingWeightHi = 13;

// solver_max_norm: out[g] = (max |u|, max |v|, 0, 0) over elements [g * kScanBlock, +kScanBlock)
// of level 0 (u and v per phyxel) or of the previous level's partials (src.xy).
struct MaxNormPush {
  uint count;  // input elements
  uint level;  // 0: read disp and vel; else src
};
PHYXEL_ASSERT_SIZE(MaxNormPush, 8);
PHYXEL_CONST uint kMaxNormBindingDisp = 0;
PHYXEL_CONST uint kMaxNormBindingVel = 1;
PHYXEL_CONST uint kMaxNormBindingSrc = 2;
PHYXEL_CONST uint kMaxNormBindingOut = 3;

// solver_motion: one object's motion, the phyxels [first, first + count): out[slot + g] =
// (sum of m |v|^2 / 2, max |v|, 0, 0) over elements [g * kScanBlock, +kScanBlock) of level 0
// (v, and the mass in ext.w) or of the previous level's partials (src.xy); the sums in a fixed
// order. slot: 0 but at the last level (one group), where it is the object's index.
struct MotionPush {
  uint first;  // level 0: the object's first phyxel; later levels 0
  uint count;  // input elements
  uint level;  // 0: read vel and ext; else src
  uint slot;
};
PHYXEL_ASSERT_SIZE(MotionPush, 16);
PHYXEL_CONST uint kMotionBindingVel = 0;
PHYXEL_CONST uint kMotionBindingExt = 1;
PHYXEL_CONST uint kMotionBindingSrc = 2;
PHYXEL_CONST uint kMotionBindingOut = 3;

#ifdef __cplusplus
}  // namespace phyxel::gpu::layout
#else
// The flat index of this invocation in a 1D dispatch() (which spreads more than
// maxComputeWorkGroupCount[0] groups over y); compare it with the element count. A macro, as
// gl_WorkGroupSize only exists after the shader's local_size declaration.
#define PHYXEL_GLOBAL_INDEX \
  (gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x)
#endif

#endif  // PHYXEL_COMPUTE_SHADERS_LAYOUT_H
