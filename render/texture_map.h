// Point-based texture mapping, the paper's section II (eqs 1-7).
//
// Step 1, texture disc <-> hemisphere (eqs 1-3): a point of the unit sphere at polar angle
// theta from the pole (0, 0, 1) maps to the texture-plane point of polar radius r and the same
// azimuth alpha, with equal area ratio c = 2 (1 - cos phi) / r^2 (eq 1), so that the whole
// unit disc covers the cap of half-angle phi:
//   u = x / sqrt(1 + z) / sqrt(1 - cos phi),  v = y / sqrt(1 + z) / sqrt(1 - cos phi)
// (Lambert's azimuthal equal-area projection). The paper calls phi a latitude, but its
// boundary condition (cap area 2 pi (1 - cos phi)) makes it the angle from the pole. With
// phi = pi/2, the paper's choice, this is eq 7 on the upper hemisphere z >= 0.
//
// Step 2, splat <-> sphere (eqs 4-6): a sphere of radius R surrounds the object, its axis
// through the object's centre; the line from a fixed point P on the axis through the splat
// centre Q, X = P + k (Q - P) (eq 4), meets the sphere where
//   k = [-2 P.(Q-P) +- sqrt(mid)] / (2 |Q-P|^2),  mid = (2 P.(Q-P))^2 - 4 |Q-P|^2 (|P|^2 - R^2)
// (eqs 5-6, coordinates relative to the sphere's centre). The paper prints the root with
// -sqrt(mid); for P inside the sphere (its simplification puts P at the centre, where
// X = k Q) that root is negative: the point behind P, on the lower hemisphere, where eq 7
// is not defined at z = -1. We take the root with +sqrt(mid), the point where the ray from P
// through Q leaves the sphere (k >= 1 for Q inside), and divide X by R to use eq 7 on the unit
// sphere. Documented in docs/scene-format.md ("Texture").
//
// Fitting (the paper leaves "appropriate" radius and height to the object's shape): the axis
// is the scene's up (+z); the sphere's centre is on the vertical line through the centre of
// the object's bounding box, at the height of the object's lowest point, so the whole object
// lies in the upper half; P is the sphere's centre; R is 1.001 x the largest distance of a
// phyxel from it. The tissue's top then maps around the texture's centre and its sides
// towards the rim.
//
// Image lookup: the texture's unit disc is the disc inscribed in the image, s = (u + 1) / 2
// to the right and t = (1 - v) / 2 downwards, in [0, 1].
#pragma once

#include <Eigen/Geometry>
#include <numbers>
#include <vector>

#include "engine/scene/scene.h"

namespace phyxel::render {

struct Dome {
  Vec3 centre = Vec3::Zero();         // the sphere's centre
  Vec3 e1 = Vec3::UnitX();            // x of eqs 4-7
  Vec3 e2 = Vec3::UnitY();            // y
  Vec3 axis = Vec3::UnitZ();          // z: towards the pole
  double radius = 1;                  // R
  double p_height = 0;                // P = centre + p_height * axis (the paper's (0, 0, z1))
  double phi = std::numbers::pi / 2;  // cap half-angle of eqs 1-3

  Vec3 to_local(const Vec3& world) const {
    const Vec3 d = world - centre;
    return {d.dot(e1), d.dot(e2), d.dot(axis)};
  }
};

// The dome of the points `rest` (an object's phyxels) as described above; `axis` is unit.
Dome fit_dome(const std::vector<Vec3>& rest, const Vec3& axis = Vec3::UnitZ());

// Eqs 4-6: the point of the unit sphere (dome coordinates divided by R) that the splat
// centre q (dome coordinates, relative to the sphere's centre) maps to. A q at P maps to the
// pole.
Vec3 sphere_point(const Vec3& q_local, double radius, double p_height);

// Eqs 2-3 (eq 7 for phi = pi/2): texture-plane (u, v) of a unit-sphere point.
Eigen::Vector2d hemisphere_uv(const Vec3& unit_point, double phi = std::numbers::pi / 2);

// Image coordinates (s, t) in [0, 1]^2 of a world point through the dome.
Eigen::Vector2d dome_texcoord(const Dome& dome, const Vec3& world);

// Gradients of s and t at `world` along the plane perpendicular to `normal` (central
// differences), for texture detail inside a splat.
Eigen::Matrix<double, 2, 3> dome_texcoord_gradient(const Dome& dome, const Vec3& world,
                                                   const Vec3& normal);

}  // namespace phyxel::render
