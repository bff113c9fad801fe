// Queries on closed triangle meshes: solid angles, closest points, and a bounding-volume
// hierarchy for fast inside tests (generalised winding number) and surface normals.
// Internal to the engine: used by shape.cpp, mesh.cpp and sampling.cpp.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "engine/geometry/mesh.h"

namespace phyxel {

// Signed solid angle (steradians) of the triangle (a, b, c) seen from the origin, by
// Van Oosterom and Strackee (1983). Positive when the triangle's counter-clockwise normal
// (b-a)x(c-a) points away from the origin. Summed over a closed outward surface it is 4 pi
// inside and 0 outside.
double triangle_solid_angle(const Vec3& a, const Vec3& b, const Vec3& c);

// Which part of a triangle a closest point lies on.
enum class TriangleFeature { Face, Vertex0, Vertex1, Vertex2, Edge01, Edge12, Edge20 };

struct ClosestPoint {
  Vec3 point = Vec3::Zero();
  double distance_squared = 0;
  TriangleFeature feature = TriangleFeature::Face;
};

// Closest point to p on the triangle (a, b, c) (Ericson, Real-Time Collision Detection 5.1.5).
ClosestPoint closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

// Generalised winding number of p by direct summation over all triangles (O(triangles)).
double winding_number_direct(const TriangleMesh& mesh, const Vec3& p);
// Distance from p to the surface by direct search over all triangles (O(triangles)).
double surface_distance_direct(const TriangleMesh& mesh, const Vec3& p);

// A BVH over one mesh, for many queries; the mesh must outlive it. Two inside tests:
//  - contains(): the generalised winding number with the far-field expansion of Barill et al.
//    2018 ("Fast winding numbers for soups and clouds"): a cluster of triangles seen from
//    further than a few times its radius contributes as one dipole (its area-weighted normal
//    sum at its area-weighted centroid); nearer triangles are summed exactly. Good at any
//    distance from the surface; the tests compare it with the direct sum.
//  - contains_near() and inside_subcells(): the sign of the outward pseudo-normal at the
//    closest surface point (Baerentzen and Aanaes 2005), exact for the closed, consistently
//    oriented surfaces that load_obj_mesh accepts. Cheap near the surface, where the winding
//    number is dearest; the cost grows with the distance to it.
// The pseudo-normal is the face normal inside a face, the mean of the two face normals on an
// edge, the angle-weighted mean of the incident face normals at a vertex.
class MeshQuery {
 public:
  explicit MeshQuery(const TriangleMesh& mesh);

  double winding_number(const Vec3& p) const;
  // Inside (winding number > 0.5) or within eps of the surface.
  bool contains(const Vec3& p, double eps) const;
  // Same answer by the closest surface point; for points near the surface.
  bool contains_near(const Vec3& p, double eps) const;
  // Which of the 4x4x4 sub-cell centres of the cube of side `side` centred on `center` are
  // inside or within eps of the surface: bit a + 4 (b + 4 c) for the centre at offset
  // ((a, b, c) + 1/2) side / 4 - side / 2. `center_inside` is the centre's own status, which
  // points with no surface nearer than the centre inherit. One search for the triangles near
  // the cube serves all the points, and octants far enough from the surface take one test.
  uint64_t inside_subcells(const Vec3& center, double side, bool center_inside, double eps) const;
  // True when some triangle lies within distance r of p.
  bool surface_within(const Vec3& p, double r) const;
  double surface_distance(const Vec3& p) const;
  // Outward unit pseudo-normal at the surface point closest to p. Features whose distance is
  // within `tie` of the closest one are summed, so a point equally close to two faces gets
  // their mean. Zero for a degenerate mesh.
  Vec3 surface_normal(const Vec3& p, double tie) const;
  const Eigen::AlignedBox3d& bounds() const { return mesh_->bounds; }

 private:
  struct Node {
    Eigen::AlignedBox3d box;
    Vec3 center = Vec3::Zero();       // area-weighted centroid
    Vec3 area_normal = Vec3::Zero();  // sum of area * unit normal
    double radius = 0;                // max distance from center to a vertex
    int32_t left = -1, right = -1;    // children; -1 for a leaf
    uint32_t first = 0, count = 0;    // leaf: triangles order_[first, first + count)
  };
  int32_t build(uint32_t first, uint32_t count);
  template <class Visit>
  bool for_each_triangle_near(const Vec3& p, double r, Visit&& visit) const;
  Vec3 vertex(uint32_t t, int k) const { return mesh_->vertices[mesh_->triangles[t][k]]; }
  // Traverses for the winding number; sets `near` when a triangle lies within eps of p.
  double winding(const Vec3& p, double eps, bool* near) const;
  Vec3 feature_normal(uint32_t t, TriangleFeature f) const;
  // Closest triangle to p nearer than sqrt(limit2); returns -1 (and leaves cp) if none.
  int64_t closest(const Vec3& p, double limit2, ClosestPoint* cp) const;
  // Inside test by the pseudo-normal at the closest point cp on triangle t.
  bool inside_by_normal(const Vec3& p, uint32_t t, const ClosestPoint& cp, double eps) const;

  const TriangleMesh* mesh_;
  std::vector<uint32_t> order_;
  std::vector<Node> nodes_;
  std::vector<Vec3> face_normals_;                   // unit
  std::vector<Vec3> vertex_normals_;                 // angle-weighted, unit
  std::unordered_map<uint64_t, Vec3> edge_normals_;  // key: edge_key(lo, hi), unit
};

inline uint64_t edge_key(uint32_t a, uint32_t b) {
  return a < b ? (uint64_t(a) << 32) | b : (uint64_t(b) << 32) | a;
}

}  // namespace phyxel
