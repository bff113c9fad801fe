// Neighbour search, step 1: the hash cell of every phyxel (cell size slightly above h, so a
// pair closer than h is at most one cell apart on every axis despite float rounding), and its
// slot in its bucket. Removed phyxels get object -1 and no slot: nobody finds them.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#define PHYXEL_NBR_FLOAT64 0
#include "solver_nbr.glsl"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { NbrPush p; };
layout(std430, binding = kNbrCellsBindingLocal) readonly buffer Local { vec4 local_pos[]; };
layout(std430, binding = kNbrCellsBindingFlags) readonly buffer Flags { uint flags[]; };
layout(std430, binding = kNbrCellsBindingClasses) readonly buffer Classes {
  SolverClass classes[];
};
layout(std430, binding = kNbrCellsBindingCellOf) writeonly buffer CellOf { ivec4 cell_of[]; };
layout(std430, binding = kNbrCellsBindingSlot) writeonly buffer Slot { uint slot[]; };
layout(std430, binding = kNbrCellsBindingBucketCount) buffer BucketCount { uint bucket_count[]; };

void main() {
  const uint i = p.first + PHYXEL_GLOBAL_INDEX;
  if (i >= p.end) return;
  const uint fl = flags[i];
  if ((fl & kFlagRemoved) != 0u) {
    cell_of[i] = ivec4(0, 0, 0, -1);
    slot[i] = 0u;
    return;
  }
  const SolverClass cls = classes[fl >> kFlagClassShift];
  const ivec3 c = cell_of_point(local_pos[i].xyz, cls.kernel.w);
  cell_of[i] = ivec4(c, int(cls.ids.x));
  // The order within a bucket depends on the atomics; rows are sorted at the end, so the
  // neighbour lists do not.
  slot[i] = atomicAdd(bucket_count[cell_bucket(c, cls.ids.x, p.bucket_mask)], 1u);
}
