// The surgery passes' part of layout.h (included at its end; the same rules): tool contact
// and its broad phase, removal edits and aspiration's reads, graspers, cutting, and the GPU
// reductions the tools' broad phase and the run loop's checks use.
#ifndef PHYXEL_COMPUTE_SHADERS_LAYOUT_SURGERY_H
#define PHYXEL_COMPUTE_SHADERS_LAYOUT_SURGERY_H

#include "layout.h"

#ifdef __cplusplus
namespace phyxel::gpu::layout {
#endif

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
  uvec4 kind;    // kToolSphere or kToolCapsule; 1 for a blade with a threshold (its point's cap
                 // takes no friction: on_sharp_point), else 0; 0, 0
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
// and the per-phyxel contact flag (1 touched, 0 not). With kContactFuseReduce the workgroup
// that finishes last (Done counts them) also writes the substep's samples as
// tool_contact_reduce does, and with kContactFuseDirtyReset empties the dirty list. With
// grasp < tools (kContactFuseReduce, one grasper, its jaws closed before this substep) it also
// does that grasper's hold (tool_grasp's kGraspHoldReduce, in the same order per phyxel): each
// candidate's invocation holds its own phyxel after its contact, the others (grid-stride) the
// held phyxels that no candidate is, and the last workgroup subtracts the grip's force from the
// sample after writing it: the same bits, one dispatch and barrier less per substep. Without
// kContactFuseReduce (the samples apart, GpuSolver::sums_apart) tool_contact_reduce does both
// beside the sever, off the substep's chain.
struct ContactPush {
  vec4 origin;         // xyz: the frame of the motion table (world, m), w unused
  uint substep;        // of the advance: the row of the samples (kContactFuseReduce)
  float dt;            // s
  uint tools;          // tools
  uint motion;         // row of the motion table (substep of the chunk, clamped to its last)
  uint hold;           // 1 past the chunk's motions: the tools stay at the row's end pose
  uint capacity;       // stride of the per-workgroup force buffer (>= its workgroups)
  uint fuse;           // kContactFuse* bits
  uint grasp;          // the grasper whose hold this pass does, or kContactNoGrasp
  uint grip_capacity;  // entries per tool of the grip buffers (GraspPush.capacity)
  uint pass;           // SeverPush.pass of this substep (the blades' kept sides)
  uint phyxels;        // SeverPush.phyxels; 0: no side kept (Sides and Quads unread)
};
PHYXEL_ASSERT_SIZE(ContactPush, 64);
PHYXEL_CONST uint kContactNoGrasp = 0xFFFFFFFFu;
PHYXEL_CONST uint kContactFuseReduce = 1;      // the samples, by the last workgroup
PHYXEL_CONST uint kContactFuseDirtyReset = 2;  // the dirty list's count 0 (alone: by one lane)
// tool_contact: {list, rest, disp, vel, ext, flags, tools, motion, force, contact, count,
// samples, dirty, done, grip, held, grip force, grip of, slot}
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
PHYXEL_CONST uint kContactBindingCount = 10;      // ContactCount (tool_broad_scan)
PHYXEL_CONST uint kContactBindingSamples = 11;    // as tool_contact_reduce's
PHYXEL_CONST uint kContactBindingDirty = 12;      // the dirty list (tool_sever, solver_force_tear)
PHYXEL_CONST uint kContactBindingDone = 13;       // workgroups finished; 0 between dispatches
PHYXEL_CONST uint kContactBindingGrip = 14;       // as kGraspBindingGrip (grasp < tools)
PHYXEL_CONST uint kContactBindingHeld = 15;       // as kGraspBindingCount
PHYXEL_CONST uint kContactBindingGripForce = 16;  // as kGraspBindingForce
PHYXEL_CONST uint kContactBindingGripOf = 17;     // as kGraspBindingGripOf
PHYXEL_CONST uint kContactBindingSlot = 18;   // uint per phyxel: its candidate slot (broad phase)
PHYXEL_CONST uint kContactBindingSides = 19;  // SeverPush's side entries, read
PHYXEL_CONST uint kContactBindingQuads = 20;  // CutQuad [row][tool] (the blades' planes)

// tool_contact_reduce: one workgroup per tool sums force[tool * capacity + k] over
// tool_contact's workgroups k, in a fixed order (thread t takes k = t, t + workgroup, ...; then a
// fixed tree) and writes samples[sample * tools + tool] = (minus the summed force: the force on the
// tool, contacts).
// With rows > 0, rows substep .. substep + rows - 1 of solver_force_tear's per-candidate rows
// (kForceContact; stride capacity x workgroup) in two dispatches: sums 0, one workgroup per
// (row, tool, 64 candidates) writes that partial by tool_contact's tree into Partials as
// tool_contact writes its own (row r at 2 r tools capacity; candidates whose phyxel is fixed or
// removed, which the force pass does not visit, add nothing, as in tool_contact); sums 1 (Force:
// those partials), one workgroup per (row, tool) adds them as above.
struct ContactReducePush {
  uint rows;  // 0: tool_contact's partials of one substep
  uint tools;
  uint capacity;       // tool_contact's workgroups: partials per tool (and row)
  uint substep;        // of the advance: the row of the samples (the first, rows > 0)
  uint sums;           // rows > 0: 0 the rows' partials, 1 the samples from them
  uint grasp;          // the grasper whose grip forces (rows: grip rows) leave its sample, or
                       // kContactNoGrasp
  uint grip_capacity;  // entries per tool of the grip buffers (ContactPush.grip_capacity)
};
PHYXEL_ASSERT_SIZE(ContactReducePush, 28);
PHYXEL_CONST uint kContactReduceGripRow = 2u;  // sums with rows 0: a grip row (the grasp's)
PHYXEL_CONST uint kContactReduceBindingForce = 0;
PHYXEL_CONST uint kContactReduceBindingSamples = 1;
PHYXEL_CONST uint kContactReduceBindingCount = 2;
PHYXEL_CONST uint kContactReduceBindingList = 3;       // candidate phyxels (rows > 0)
PHYXEL_CONST uint kContactReduceBindingFlags = 4;      // (rows > 0)
PHYXEL_CONST uint kContactReduceBindingPartials = 5;   // written with rows > 0, sums 0
PHYXEL_CONST uint kContactReduceBindingHeld = 6;       // the grip's count per tool (grasp)
PHYXEL_CONST uint kContactReduceBindingGripForce = 7;  // the grip's forces (grasp)

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
  vec4 blade_lo;     // xyz: the blades' swept bounds min (m); w: 1 where every hit is near them
  vec4 blade_hi;     // xyz: the blades' swept bounds max (m)
};
PHYXEL_ASSERT_SIZE(BroadPhasePush, 80);
// tool_broad_phase's mode 0 marks a workgroup's count with it where a hit lies within the
// blades' swept bounds grown by the margin; tool_broad_scan dispatches no sever without one.
PHYXEL_CONST uint kBroadBladeNear = 0x80000000u;
PHYXEL_CONST uint kBroadBindingList = 0;  // force list
PHYXEL_CONST uint kBroadBindingRest = 1;
PHYXEL_CONST uint kBroadBindingDisp = 2;
PHYXEL_CONST uint kBroadBindingFlags = 3;
PHYXEL_CONST uint kBroadBindingMaxNorm = 4;  // vec4 (max |u|, max |v|, 0, 0)
PHYXEL_CONST uint kBroadBindingGroup = 5;    // uint per workgroup: hits (mode 0), offset (1)
PHYXEL_CONST uint kBroadBindingOut = 6;      // candidate list
PHYXEL_CONST uint kBroadBindingSlot = 7;     // uint per phyxel: its candidate slot, or ~0 (mode 1)
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
// tool_broad_scan writes after the ContactCount: tool_sever's indirect dispatch (lanes
// invocations per candidate; none without candidates).
struct SeverGroups {
  uint x;
  uint y;
  uint z;
  uint lanes;  // invocations per candidate: kSeverMaxLanes, halved while the candidates times
               // the lanes exceed kSeverInvocations (at least 1)
};
PHYXEL_ASSERT_SIZE(SeverGroups, 16);

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
//   kGraspHoldReduce  kGraspHold, then the workgroup that finishes last (Done counts them)
//                  does kGraspReduce: one dispatch and barrier less (no workgroup where nothing
//                  is held, which changes no bit of the sample: x - 0 is x, z is 0 already)
PHYXEL_CONST uint kGraspCapture = 0u;
PHYXEL_CONST uint kGraspHold = 1u;
PHYXEL_CONST uint kGraspReduce = 2u;
PHYXEL_CONST uint kGraspHoldReduce = 3u;
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
PHYXEL_CONST uint kGraspBindingDone = 12;  // workgroups finished (tool_contact's); 0 between
// uint [tool][capacity] per phyxel: its entry in the tool's grip, written by the capture (and
// restore_grips); stale where not held, so a reader checks grip[entry].phyxel and the count.
PHYXEL_CONST uint kGraspBindingGripOf = 13;

// ---------------------------------------------------------------------------------------
// Cutting (compute/gpu_solver_cutting.cpp; shaders/tool_sever.comp mirrors
// engine/solver/cpu_solver_cutting.cpp and engine/solver/cutting.cpp).

// The quad one tool's blade swept in one substep (engine swept_quad), relative to the contact
// origin, row-major [row][tool]; rows are the chunk's substeps then one for holding the last
// pose. edge.w: the cut force threshold (N), negative for a tool without a blade. axis and
// resist: the edge's resistance (engine EdgeFrame; the body's radius p0.w, the kept sides' band
// p1.w: engine side_band; the blade's tip is p3 + p3.w edge): the axis at the end pose (w
// unused) and (stiffness N/m^3, 0 where nothing is held; depth m; the tip's and the end's
// motion along the edge, m). The EdgeFrame (the point's in a stab): frame_tip (w: its
// length), frame_axis (w: its front), frame_edge (w: 1 where the blade advances in the substep,
// engine blade_advances: a blade in the cutting state goes on cutting, else 0).
struct CutQuad {
  vec4 p0;
  vec4 p1;
  vec4 p2;
  vec4 p3;
  vec4 edge;
  vec4 axis;
  vec4 resist;
  vec4 frame_tip;
  vec4 frame_axis;
  vec4 frame_edge;
};
PHYXEL_ASSERT_SIZE(CutQuad, 160);

// tool_sever: SeverGroups.lanes invocations per candidate, after tool_contact_reduce: for every
// tool whose sample of this substep presses its edge with at least its threshold, each
// candidate's invocations test its live pairs (every lanes-th each; canonical order, lower index
// first) against the tool's quad, a pair going to the first tool that crosses it (and, whatever
// the force, against a blade with a threshold whose edge carries them past its reach). The pair's
// slot in the lower index's row is claimed by an atomic exchange (so each pair is severed and
// logged once); the winner zeroes both slots, logs (i, j, t) and puts both phyxels in the dirty
// list (once each, by kFlagCutDirty). The workgroup that finishes last (Done counts them) runs
// solver_precompute's per-phyxel work over the dirty list (pair_edit.glsl: a short list with
// several lanes loading each phyxel's pairs). Its indirect dispatch follows the
// ContactCount in the candidates' count buffer (tool_broad_scan: SeverGroups).
// A few candidates' pairs are tested all at once (a pair's test at a time, latency-bound); many
// candidates fill the card with fewer lanes each, which repeat less of a candidate's setup.
// Its workgroup is wider than the others': the last one reruns the dirty list's precompute
// (a Jacobi decomposition per phyxel on one lane), which a cut through many pairs makes long.
PHYXEL_CONST uint kSeverWorkgroupSize = 256u;
PHYXEL_CONST uint kSeverMaxLanes = 32u;
PHYXEL_CONST uint kSeverInvocations = 131072u;
struct SeverPush {
  vec4 origin;  // the motion table's frame (ContactPush.origin)
  uint tools;
  uint row;         // row of the cut table
  uint sample_row;  // substep of the advance (its sample is rows 2 (substep tools + tool), +1)
  uint log_capacity;
  uint pass;     // the substep's count for the side entries (engine cutting.h side_entry)
  uint phyxels;  // the stride of the side entries [tool][phyxel]
  // Beside the stress pass (stress_epoch != 0, its StressPush.epoch: the count of written
  // workgroups at which that pass has ended): the last workgroup waits for that pass's end,
  // then redoes the stress of the dirty list's phyxels in its list (of stress_count,
  // ascending) with its lanes and weights mode (StepPush).
  uint stress_epoch;
  uint stress_lanes;
  uint stress_count;
  uint stress_weights;
  uint pad0, pad1;
};
PHYXEL_ASSERT_SIZE(SeverPush, 64);
// The most polls of that pass's epoch (Vulkan does not promise that the pass recorded first runs
// beside or before the sever): an atomic's round trip (~0.1-1 us) makes it 0.4 s or more on a
// GPU, far past a stress pass (7 us on the breast, ms at tens of millions of phyxels); llvmpipe
// ends any loop after 65 535 iterations (milliseconds). Where they run out, the sever sets
// kCutLogStressMissed in the log header's y, skips the redo, and the advance's later severs do
// not wait; GpuSolver::finish_cutting throws.
PHYXEL_CONST uint kSeverStressWaitSpins = 1u << 22;
PHYXEL_CONST uint kCutLogStressMissed = 1u;
PHYXEL_CONST uint kSeverBindingList = 0;  // candidates
PHYXEL_CONST uint kSeverBindingRest = 1;
PHYXEL_CONST uint kSeverBindingDisp = 2;
PHYXEL_CONST uint kSeverBindingOffset = 3;
PHYXEL_CONST uint kSeverBindingIndex = 4;
PHYXEL_CONST uint kSeverBindingWeight = 5;  // the pair weights, as uint bits
PHYXEL_CONST uint kSeverBindingFlags = 6;
PHYXEL_CONST uint kSeverBindingQuads = 7;    // CutQuad [row][tool]
PHYXEL_CONST uint kSeverBindingSamples = 8;  // vec4 [substep][tool]: force on the tool
PHYXEL_CONST uint kSeverBindingDirty = 9;    // uint: count, then phyxels
// uvec4: (count, kCutLogStressMissed or 0, 0, 0), then (i, j, t bits, torn)
PHYXEL_CONST uint kSeverBindingLog = 10;
PHYXEL_CONST uint kSeverBindingCount = 11;  // ContactCount, then SeverGroups
PHYXEL_CONST uint kSeverBindingIndexHi = 12;
PHYXEL_CONST uint kSeverBindingWeightHi = 13;
PHYXEL_CONST uint kSeverBindingLocal = 14;  // the precompute's (kPrecomputeBinding*)
PHYXEL_CONST uint kSeverBindingClasses = 15;
PHYXEL_CONST uint kSeverBindingAinv = 16;
PHYXEL_CONST uint kSeverBindingResid = 17;
PHYXEL_CONST uint kSeverBindingDone = 18;    // workgroups done (solver_force_tear's too); 0 between
PHYXEL_CONST uint kSeverBindingSides = 19;   // uint [tool][phyxel]: side entries (blade_edge.glsl)
PHYXEL_CONST uint kSeverBindingStress = 20;  // beside the stress pass: its D (vec4[3 N])
PHYXEL_CONST uint kSeverBindingStressList = 21;  // ... its list
PHYXEL_CONST uint kSeverBindingStressDone = 22;  // ... its Done (kStressBindingDone)

// tool_resist: over the candidates, after tool_contact and before tool_contact_reduce (the
// CPU twin is CpuSolver::apply_edge_resistance): each candidate that is neither fixed nor
// removed sums the forces of the pairs each blade's edge holds (canonical order, its share),
// adds dt / m times them to its velocity, and each workgroup adds its candidates' sums per tool
// to tool_contact's partial force[tool * capacity + group]. With fuse kContactFuseReduce the
// workgroup that finishes last writes the samples as tool_contact_reduce does (and with
// kContactFuseDirtyReset empties the dirty list), in place of that dispatch.
struct ResistPush {
  vec4 origin;  // the motion table's frame (ContactPush.origin)
  float dt;     // s
  uint tools;
  uint row;       // row of the cut table (SeverPush.row)
  uint capacity;  // stride of the partial force buffer (ContactPush.capacity)
  uint substep;   // of the advance: the row of the samples (kContactFuseReduce)
  uint fuse;      // kContactFuse* bits (kContactFuseReduce, kContactFuseDirtyReset)
  uint pass;      // SeverPush.pass of this substep
  uint phyxels;   // SeverPush.phyxels
};
PHYXEL_ASSERT_SIZE(ResistPush, 48);
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
PHYXEL_CONST uint kResistBindingSamples = 14;  // written with kContactFuseReduce
PHYXEL_CONST uint kResistBindingDone = 15;     // workgroups done (tool_contact's); 0 between
PHYXEL_CONST uint kResistBindingDirty = 16;    // the dirty list (kContactFuseDirtyReset)
PHYXEL_CONST uint kResistBindingSides = 17;    // SeverPush's side entries, read

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
#endif

#endif  // PHYXEL_COMPUTE_SHADERS_LAYOUT_SURGERY_H
