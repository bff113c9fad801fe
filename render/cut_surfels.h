// Cut-face surfels: what the renderer draws where a cut opened the tissue (the faces come from
// engine/surgery/cut_faces.h; SplatRenderer::update_cut_surfels appends or replaces them).
//
// One surfel per phyxel a cut touched, on top of its outer-surface surfel if it has one:
//   index     the phyxel (its disc moves with it through the deform pass)
//   flags     kSurfelCutFace (the accumulation pass draws cut tissue, the shading pass wets it)
//   normal    the face normal in rest space (out of the phyxel's piece); w: the offset from the
//             phyxel to the face's plane along it, so the disc lies on the cut, not inside the
//             piece (the deform pass carries the offset through F)
//   radius    kSplatRadiusSpacings x the object's spacing: what the sampler gives the object's
//             surface phyxels (interior phyxels have splat radius 0); half that on phyxels of
//             the outer surface (the face's rim), so the face overhangs the outer surface less
//   s, t      the face's own rest-plane coordinates in spacings (s along the fibres: the
//             projection of the object's x axis, or y for faces across x), with their
//             gradients, for the procedural cut tissue of shaders/cut_tissue.glsl
//
// A torn face (CutFace::torn: a pair of the phyxel was torn by its stress) is drawn rough
// (docs/tearing.md): flags kSurfelTornFace as well; the disc is displaced along the face normal
// by h, 3-D noise at its rest centre (rough_surfel of engine/surgery/fracture_surface.h with
// torn_face_noise), and tilted to the displaced surface's normal n'; normal.w is then
// (offset + h) / (n . n'), which puts the centre on the displaced surface's tangent plane while
// the deform pass moves it along n'. Its radius is kTornRadiusScale times a cut face's, so
// neighbouring discs still overlap where the noise displaces them differently. A torn pair face
// has no fracture sphere: the roughness has no falloff on it (FractureRegion with radius 0);
// a suction fracture passes its sphere.
#pragma once

#include <cstdint>
#include <vector>

#include "engine/sampling/phyxel_set.h"
#include "engine/surgery/cut_faces.h"
#include "engine/surgery/fracture_surface.h"
#include "render/shaders/render_layout.h"

namespace phyxel::render {

// The roughness of torn faces, in the object's spacing s: amplitude 0.3 s, a base wavelength of
// 3 s (frequency 1 / (3 s)), two octaves of persistence 0.5; the seed differs per object.
inline constexpr double kTornAmplitudeSpacings = 0.3;
inline constexpr double kTornWavelengthSpacings = 3.0;
inline constexpr double kTornRadiusScale = 1.25;
NoiseParams torn_face_noise(double spacing, uint32_t object);

layout::SurfelStatic cut_face_surfel(const PhyxelSet& set, uint32_t phyxel, const CutFace& face,
                                     const FractureRegion& region = {});

// The surfels of `phyxels` that have a face and are not removed (CutFaces::take_changed()
// gives the ones to update).
std::vector<layout::SurfelStatic> cut_face_surfels(const PhyxelSet& set, const CutFaces& faces,
                                                   const std::vector<uint32_t>& phyxels);

}  // namespace phyxel::render
