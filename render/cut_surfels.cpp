#include "render/cut_surfels.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "engine/sampling/splat_radius.h"

namespace phyxel::render {
namespace {

layout::vec4 vec4_of(const Vec3& v, double w) {
  return {static_cast<float>(v.x()), static_cast<float>(v.y()), static_cast<float>(v.z()),
          static_cast<float>(w)};
}

// A torn face's seed: a fixed base, one per object.
constexpr uint64_t kTornSeed = 0x7f4a7c159e3779b9ull;

}  // namespace

NoiseParams torn_face_noise(double spacing, uint32_t object) {
  NoiseParams p;
  p.seed = kTornSeed + object;
  p.frequency = 1.0 / (kTornWavelengthSpacings * spacing);
  p.amplitude = kTornAmplitudeSpacings * spacing;
  p.octaves = 2;
  p.persistence = 0.5;
  return p;
}

layout::SurfelStatic cut_face_surfel(const PhyxelSet& set, uint32_t phyxel, const CutFace& face,
                                     const FractureRegion& region) {
  const ObjectRange& object = set.objects.at(set.object.at(phyxel));
  const double spacing = object.spacing;
  const Vec3& n = face.normal;
  // The fibres run along the object's x axis as seen on the face (y on faces across x): the
  // same direction on neighbouring discs of one face, so the fibres continue from disc to disc.
  const Vec3 along = std::abs(n.x()) < 0.95 ? Vec3::UnitX() : Vec3::UnitY();
  const Vec3 t1 = (along - n * n.dot(along)).normalized();
  const Vec3 t2 = n.cross(t1);
  const Vec3 centre = set.rest[phyxel] + face.offset * n;  // the disc's centre at rest
  layout::SurfelStatic s{};
  s.index = phyxel;
  // On a phyxel of the outer surface the disc sits on the rim of the cut face and would stick
  // out past the outer surface by its whole radius (seen obliquely, a red fringe over the
  // outer surface): half the radius there; the next row in, a spacing away, covers the rim.
  const bool rim = (set.flags[phyxel] & kSurface) != 0;
  s.radius = static_cast<float>(kSplatRadiusSpacings * spacing * (rim ? 0.5 : 1.0));
  s.support = static_cast<float>(object.support_radius);
  s.flags = (set.flags[phyxel] & ~(layout::kSurfelCutFace | layout::kSurfelTornFace)) |
            layout::kSurfelCutFace;
  s.normal = vec4_of(n, face.offset);
  if (face.torn) {
    const RoughSurfel rough =
        rough_surfel(torn_face_noise(spacing, set.object.at(phyxel)), region, centre, n);
    // n . n' >= 0.5 (a tilt of 60 degrees at most) keeps the centre's slide along n' bounded.
    const double cosine = std::max(0.5, n.dot(rough.normal));
    s.flags |= layout::kSurfelTornFace;
    s.normal = vec4_of(rough.normal, (face.offset + rough.displacement) / cosine);
    s.radius *= static_cast<float>(kTornRadiusScale);
  }
  s.ds_dx = vec4_of(t1 / spacing, centre.dot(t1) / spacing);
  s.dt_dx = vec4_of(t2 / spacing, centre.dot(t2) / spacing);
  return s;
}

std::vector<layout::SurfelStatic> cut_face_surfels(const PhyxelSet& set, const CutFaces& faces,
                                                   const std::vector<uint32_t>& phyxels) {
  std::vector<layout::SurfelStatic> out;
  out.reserve(phyxels.size());
  for (const uint32_t k : phyxels) {
    const CutFace* face = faces.face(k);
    if (face != nullptr && (set.flags[k] & kRemoved) == 0)
      out.push_back(cut_face_surfel(set, k, *face));
  }
  return out;
}

}  // namespace phyxel::render
