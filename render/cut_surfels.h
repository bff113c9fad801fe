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
#pragma once

#include <cstdint>
#include <vector>

#include "engine/sampling/phyxel_set.h"
#include "engine/surgery/cut_faces.h"
#include "render/shaders/render_layout.h"

namespace phyxel::render {

layout::SurfelStatic cut_face_surfel(const PhyxelSet& set, uint32_t phyxel, const CutFace& face);

// The surfels of `phyxels` that have a face and are not removed (CutFaces::take_changed()
// gives the ones to update).
std::vector<layout::SurfelStatic> cut_face_surfels(const PhyxelSet& set, const CutFaces& faces,
                                                   const std::vector<uint32_t>& phyxels);

}  // namespace phyxel::render
