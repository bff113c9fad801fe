// The cutting force a scalpel's user feels (the paper's eqs 21-26; docs/cutting.md, "The
// cutting force"), from what the blade felt in one substep.
//
// F_x is the tissue's force on the blade (the contact reaction: ToolContactSample::force). It
// splits against the blade's plane (spanned by its axis and its edge; normal n):
//   F_p = (F_x . n) n          the part perpendicular to the plane (eq 22: |F_x| cos theta)
//   F_l = F_x - F_p            the part within it (eq 21: |F_x| sin theta)
// with theta the contact angle between F_x and n. The paper's velocity v enters as the
// direction of the friction: the blade's faces slide through the tissue along the part of the
// blade's velocity within its plane, and the cut faces pressing on them drag against it:
//   f_p = mu |F_p|             (eq 26: Coulomb friction of the faces pressed by F_p)
//   f_l = mu |F_l| d / length  (eq 25)
//   f_c = -(f_l + f_p) v_hat   (eq 24)
// d is the penetration depth: the length of the blade in the tissue (the range along the axis,
// within the blade, of the phyxels in contact or within a spacing of it). The paper's eq 25
// multiplies by d in metres, which is not a force; d / length (the fraction of the blade embedded)
// keeps it one and equals the paper's form for a blade of unit length. The hand feels F_x + f_c:
// the contact reaction (tissue pushed aside and the edge's resistance) plus the drag of the cut
// faces on the flanks, which point contact does not resolve when the blade is thinner than the
// phyxel spacing. f_c is not applied back to the tissue.
#pragma once

#include <cstdint>

#include "engine/scene/tool_desc.h"
#include "engine/solver/contact.h"

namespace phyxel {

struct CutFeedback {
  double cut_force = 0;          // N, compared with the threshold (solver/cutting.h, cut_force)
  double theta = 0;              // rad, the contact angle between F_x and the plane's normal
  double in_plane = 0;           // N, |F_l|
  double normal = 0;             // N, |F_p|
  double depth = 0;              // m, d
  Vec3 friction = Vec3::Zero();  // N, f_c (zero while the blade does not slide in its plane)
};

// The feedback of one substep in which the blade moved `motion` and felt `sample` (with its
// axial range of contacts, ToolContactSample::axial_min/max, from the tip at the end pose). mu
// is the tool's friction. Without contacts the forces are zero (the depth need not be).
CutFeedback cut_feedback(const Blade& blade, double mu, const ToolMotion& motion,
                         const ToolContactSample& sample);

}  // namespace phyxel
