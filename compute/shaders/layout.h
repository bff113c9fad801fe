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
// In the current substep's dirty list (tool_sever, solver_force_tear); its precompute clears it.
PHYXEL_CONST uint kFlagCutDirty = 1024u;
// Set by solver_precompute: left without a fit (engine/solver/tearing.h left_without_fit:
// regularised after it lost a pair, not fixed); solver_force_tear severs every pair it still has.
PHYXEL_CONST uint kFlagNoFit = 2048u;
// Integrated by the SCNI band (layout_band.h): its precompute gives it no elastic volume and no
// hourglass stiffness (its energy is its band boxes').
PHYXEL_CONST uint kFlagBand = 4096u;
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
  uint indexed;  // 1: phyxel = list[invocation]; 0: phyxel = first + invocation
  uint first;    // indexed 0: the phyxel of invocation 0 (the setup runs in chunks)
  uint pad;
};
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
// solver_stress: {offset, index, weight, local, disp, ainv, resid, flags, classes, stress, list,
// principal, cauchy}; stress = D_i as 3 vec4 columns (xyz; w = u_i). With mode
// kStressWithPrincipal (GpuSolver::set_principal_stress on) also principal[i] = the largest
// principal value of the Cauchy stress of phyxel i (float, Pa), and with kStressWithTensor
// (tearing on) the symmetrised tensor into cauchy[2 i] = (xx, yy, zz, xy), cauchy[2 i + 1] =
// (xz, yz, 0, 0): one gather for the three. Buffers not written are bound by stand-ins.
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
PHYXEL_CONST uint kStressBindingList = 10;       // the stress pass list
PHYXEL_CONST uint kStressBindingPrincipal = 11;  // float per phyxel
PHYXEL_CONST uint kStressBindingCauchy = 12;     // vec4[2 N]
PHYXEL_CONST uint kStressBindingIndexHi = 13;
PHYXEL_CONST uint kStressBindingWeightHi = 14;
// uint: the workgroups written of the advance's passes beside a sever (StressPush).
PHYXEL_CONST uint kStressBindingDone = 15;
// solver_stress's push: with epoch != 0 each workgroup adds 1 to Done once its stress is
// written; tool_sever beside it waits for the count `epoch` (every workgroup of the advance's
// passes beside a sever so far) to redo the stress of the phyxels it severed pairs of
// (GpuSolver's sever beside the stress pass).
struct StressPush {
  StepPush step;
  uint epoch;
};
PHYXEL_ASSERT_SIZE(StressPush, 24);
PHYXEL_CONST uint kStressOnly = 0u;           // StepPush.mode of solver_stress
PHYXEL_CONST uint kStressWithPrincipal = 1u;  // ... and the largest principal stress
PHYXEL_CONST uint kStressWithTensor = 2u;     // ... and the Cauchy tensor (tearing)
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

// solver_force_tear (engine/solver/tearing.h): the force pass (StepPush's first five fields, the
// kForceBinding* bindings) over the force list, then the tear test over that list and the
// stress pass's phyxels not in it (`tear_only` more entries of the same list buffer), on the u
// the stress pass read: a pair whose mean normal stress reaches the mean of the two classes'
// tear_stress gets weight 0 in both slots, is logged as (i, j, 0.5 bits, 1) in the cut log and
// puts both phyxels in the dirty list (tool_sever's); the workgroup that finishes last (Done
// counts them) clears the torn pairs' second slots and runs solver_precompute's per-phyxel
// work over the dirty list.
struct ForceTearPush {
  uint count;  // force pass list length
  float dt;
  uint mode;
  uint weights;
  uint lanes;      // invocations per phyxel, for the force and the tear test (>= 1)
  uint tear_only;  // stress pass phyxels after the force list: the tear test alone
  uint log_capacity;
  float weakest;  // the smallest tear strength of any class that tears
  // With kForceContact in contact_fuse (mode kForceKickDrift): tool_contact's work for the
  // next substep after the drift, per candidate of the force list (ContactPush's fields), its
  // forces and ranges per candidate into row contact_row of the rows buffer (stride
  // contact_stride), which tool_contact_reduce sums after the advance's last force pass.
  vec4 contact_origin;
  uint contact_row;     // the substep of the advance whose contact this is
  uint contact_motion;  // row of the motion table
  uint contact_hold;
  uint contact_tools;
  uint contact_stride;  // candidates per row and tool (a multiple of the workgroup)
  uint contact_fuse;    // kForceContact, kForceContactDirtyReset
  // solver_force_contact: the grasper whose hold follows the contact (kContactNoGrasp: none),
  // and the grip buffers' entries per tool (ContactPush's grasp and grip_capacity).
  uint contact_grasp;
  uint grip_capacity;
};
PHYXEL_ASSERT_SIZE(ForceTearPush, 80);
PHYXEL_CONST uint kForceContact = 1u;
PHYXEL_CONST uint kForceContactDirtyReset = 2u;  // the last workgroup empties the dirty list
PHYXEL_CONST uint kForceTearBindingRest = 15;
PHYXEL_CONST uint kForceTearBindingPrincipal = 16;  // float per phyxel (solver_stress)
PHYXEL_CONST uint kForceTearBindingCauchy = 17;     // vec4[2 N] (solver_stress)
PHYXEL_CONST uint kForceTearBindingDirty = 18;      // tool_sever's dirty list
PHYXEL_CONST uint kForceTearBindingLog = 19;        // the cut log
PHYXEL_CONST uint kForceTearBindingAinv = 20;       // the precompute's (kPrecomputeBinding*)
PHYXEL_CONST uint kForceTearBindingResid = 21;
PHYXEL_CONST uint kForceTearBindingDone = 22;     // workgroups finished; 0 between dispatches
PHYXEL_CONST uint kForceTearBindingSlot = 23;     // uint per phyxel: its candidate slot
PHYXEL_CONST uint kForceTearBindingCount = 24;    // ContactCount (tool_broad_scan)
PHYXEL_CONST uint kForceTearBindingTools = 25;    // ContactToolShape per tool
PHYXEL_CONST uint kForceTearBindingMotion = 26;   // the motion table
PHYXEL_CONST uint kForceTearBindingRows = 27;     // vec4 [row][2][tool][contact_stride]
PHYXEL_CONST uint kForceTearBindingContact = 28;  // the contact flags
// solver_force_contact: the force pass (kForceBinding*) with the contact, no tear test
// (ForceTearPush; kForceContactDirtyReset by one invocation), and the grasper's hold.
PHYXEL_CONST uint kForceContactBindingRest = 15;
PHYXEL_CONST uint kForceContactBindingSlot = 16;
PHYXEL_CONST uint kForceContactBindingCount = 17;
PHYXEL_CONST uint kForceContactBindingTools = 18;
PHYXEL_CONST uint kForceContactBindingMotion = 19;
PHYXEL_CONST uint kForceContactBindingRows = 20;
PHYXEL_CONST uint kForceContactBindingContact = 21;
PHYXEL_CONST uint kForceContactBindingDirty = 22;      // tool_sever's dirty list
PHYXEL_CONST uint kForceContactBindingGrip = 23;       // GraspEntry [tool][grip_capacity]
PHYXEL_CONST uint kForceContactBindingHeld = 24;       // ContactCount per tool: the grips' sizes
PHYXEL_CONST uint kForceContactBindingGripForce = 25;  // vec4 per grip entry
PHYXEL_CONST uint kForceContactBindingGripOf = 26;     // uint [tool][phyxel]: its grip entry
PHYXEL_CONST uint kForceContactBindingInForce = 27;    // a bit per phyxel: in the force list

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

#ifdef __cplusplus
}  // namespace phyxel::gpu::layout
#else
// The flat index of this invocation in a 1D dispatch() (which spreads more than
// maxComputeWorkGroupCount[0] groups over y); compare it with the element count. A macro, as
// gl_WorkGroupSize only exists after the shader's local_size declaration.
#define PHYXEL_GLOBAL_INDEX \
  (gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x)
#endif

#include "layout_surgery.h"  // the surgery passes' structs and bindings

#endif  // PHYXEL_COMPUTE_SHADERS_LAYOUT_H
