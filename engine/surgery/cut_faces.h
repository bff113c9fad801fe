// The faces a cut leaves inside the tissue, per phyxel, in rest space (what the renderer draws
// as cut-face surfels: render/cut_surfels.h).
//
// A severed pair (i, j, t) crossed the blade at p = x0_i + t (x0_j - x0_i). Both of its
// phyxels now border the cut there: i's face and j's face each get p as a crossing point. Per
// phyxel the face is
//   normal  the least-squares plane of its crossing points, pointing from the phyxel toward
//           them (out of its own piece: i's face toward j, j's toward i). The paper's
//           eqs 18-20 fit z = a0 x + a1 y + a2, which cannot represent a plane parallel to z;
//           we fit the total-least-squares plane instead (through the centroid, normal the
//           eigenvector of the smallest eigenvalue of the points' covariance), which is the
//           same plane for points on a plane and works for every orientation. With fewer than
//           3 points, or collinear ones, no plane is defined: the normal is then the normalised
//           mean of (crossing point - x0).
//   centre  the centroid of the crossing points, and `offset`, the distance from x0 to the
//           fitted plane along the normal (where a disc on the face is centred).
// Faces only grow: a pair severed later adds its point and the face is refitted.
// A face with at least one torn pair (stress, not a blade) is `torn`: the renderer draws it
// rough and bloody (render/cut_surfels.h, docs/tearing.md).
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "engine/sampling/phyxel_set.h"
#include "engine/solver/cutting.h"

namespace phyxel {

struct CutFace {
  std::vector<Vec3> points;  // crossing points in rest space (m), in the order severed
  Vec3 centroid = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();  // unit, rest space, out of the phyxel's piece
  double offset = 0;            // (centroid - x0) . normal: the plane's distance from x0, m
  bool fitted = false;          // true: a plane fit; false: the mean-direction fallback
  Vec3 toward = Vec3::Zero();   // sum of the unit directions from x0 to the severed partners
  bool torn = false;            // at least one of its pairs was torn (SeveredPair::torn), not cut
};

class CutFaces {
 public:
  // Adds the crossing points of `pairs` (indices into `set`, i < j as the solver logs them)
  // to both phyxels' faces and refits those faces. Throws std::invalid_argument for an index
  // outside the set or a pair with i == j.
  void add(const PhyxelSet& set, const std::vector<SeveredPair>& pairs);

  // The phyxels whose face was created or changed since the last call, ascending; clears the
  // list.
  std::vector<uint32_t> take_changed();

  // The face of `phyxel`, or null when no cut touches it.
  const CutFace* face(uint32_t phyxel) const;
  size_t size() const { return faces_.size(); }  // phyxels with a face

  // The normal of crossing points seen from x0 (the rule above). `toward` (the directions to
  // the severed partners) orients it when the points give no side: a point at x0 itself, or
  // x0 in the fitted plane.
  static Vec3 fit_normal(const Vec3& x0, const std::vector<Vec3>& points, const Vec3& toward,
                         bool* fitted = nullptr);

 private:
  std::unordered_map<uint32_t, CutFace> faces_;
  std::vector<uint32_t> changed_;
};

}  // namespace phyxel
