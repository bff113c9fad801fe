// Cube mirror environment mapping, the paper's section VI step 3 (eqs 33-34): a square image
// of the surroundings (the texture plane) is put on a cube of side D = 2 (half side 1), its
// middle square on the top face and the ring around it on the four sides:
//
//   top face (z = 1):      (u, v) = sqrt(K) (x, y)
//   side faces (|x| or |y| = 1, -1 <= z <= 1):
//                          (u, v) = (x, y) sqrt(K + 2/K - 4 z / (K D))        (eqs 33, 34)
//
// K the ratio of the texture's area to the cube's on the top face. The sides' factor runs
// from sqrt(K) at their top edge (continuous with the top face) to sqrt(K + 4/K) at their
// bottom edge, the image's border: the texture plane is the square |u|, |v| <= sqrt(K + 4/K),
// and u^2 is linear in z, so each band of a side gets an equal share of the ring. The paper
// leaves the bottom face (z = -1) bare; here it shows the middle square again, as the top
// face seen in a mirror at the cube's mid-plane, so that no direction is empty.
//
// The cube is at infinity (only directions matter) and fixed in the world: its frame is the
// scene camera's at the start, +z (the top face, the image's centre) along the view, +x to the
// camera's right, +y down, so the frames' background shows the image upright around the
// target and a mirror surface facing the camera shows the middle square (the bottom face).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "engine/scene/scene.h"
#include "render/camera.h"
#include "render/image.h"

namespace phyxel::render {

// The image coordinates (s, t) in [0, 1]^2 (s to the right, t down from the top row) of the
// cube point that direction `d` (cube frame, any length > 0) points at, for area ratio k > 0.
Eigen::Vector2d environment_st(const Vec3& d, double k);

// World -> cube frame: rows right, -true_up, forward of `camera`.
Eigen::Matrix3d environment_basis(const Camera& camera);

// The environment image of `file`: a PNG or JPEG whose width equals its height (the texture
// plane is a square). Throws SceneError "CONTEXT: problem; allowed ..." otherwise.
RgbaImage load_environment(const std::filesystem::path& file, const std::string& context);

// `mirror` per material index of the PhyxelSet sample_scene makes from `scene` (objects'
// materials first, then every object's inclusions in order).
std::vector<double> material_mirrors(const Scene& scene);

}  // namespace phyxel::render
