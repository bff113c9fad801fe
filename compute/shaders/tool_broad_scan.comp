// The broad phase's workgroup counts into exclusive offsets (tool_broad_phase), in one
// workgroup: thread t scans a contiguous run of the counts, a fixed tree over the threads'
// totals gives each run's start. Writes the total, tool_contact's indirect dispatch and
// tool_sever's (SeverGroups.lanes invocations per candidate; none where no count carries
// kBroadBladeNear: no candidate within the blades' reach).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { BroadPhasePush p; };
layout(std430, binding = kBroadScanBindingGroup) buffer Group { uint group[]; };
layout(std430, binding = kBroadScanBindingCount) writeonly buffer Count {
  ContactCount count;
  SeverGroups sever;
};

shared uint run_total[PHYXEL_WORKGROUP_SIZE];
shared uint any_near;  // kBroadBladeNear where a count carries it

void main() {
  const uint t = gl_LocalInvocationID.x;
  const uint per = (p.groups + PHYXEL_WORKGROUP_SIZE - 1u) / PHYXEL_WORKGROUP_SIZE;
  const uint first = min(t * per, p.groups), last = min(first + per, p.groups);
  if (t == 0u) any_near = 0u;
  barrier();
  uint sum = 0u, near = 0u;
  for (uint k = first; k < last; ++k) {
    sum += group[k] & ~kBroadBladeNear;
    near |= group[k] & kBroadBladeNear;
  }
  run_total[t] = sum;
  if (near != 0u) atomicOr(any_near, near);
  barrier();
  for (uint d = 1u; d < PHYXEL_WORKGROUP_SIZE; d <<= 1u) {
    const uint add = t >= d ? run_total[t - d] : 0u;
    barrier();
    run_total[t] += add;
    barrier();
  }
  uint offset = run_total[t] - sum;  // exclusive start of this thread's run
  for (uint k = first; k < last; ++k) {
    const uint hits = group[k] & ~kBroadBladeNear;
    group[k] = offset;
    offset += hits;
  }
  if (t == PHYXEL_WORKGROUP_SIZE - 1u) {
    const uint total = run_total[t];
    count.total = total;
    // As dispatch() spreads groups over y past 65535 (PHYXEL_GLOBAL_INDEX); at least one,
    // whose last workgroup writes the samples (kContactFuseReduce).
    const uint groups = max((total + PHYXEL_WORKGROUP_SIZE - 1u) / PHYXEL_WORKGROUP_SIZE, 1u);
    count.groups_x = min(groups, 65535u);
    count.groups_y = (groups + 65534u) / 65535u;
    count.groups_z = 1u;
    uint lanes = kSeverMaxLanes;
    while (lanes > 1u && total * lanes > kSeverInvocations) lanes /= 2u;
    const uint sever_groups =
        any_near != 0u ? (total * lanes + kSeverWorkgroupSize - 1u) / kSeverWorkgroupSize : 0u;
    sever = SeverGroups(min(sever_groups, 65535u), max((sever_groups + 65534u) / 65535u, 1u), 1u,
                        lanes);
  }
}
