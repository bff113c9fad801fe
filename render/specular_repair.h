// The paper's video preprocessing, step 1 (section VI): specular spots of a surgery video's
// frame found and repaired, so that the texture shows no glints that stay put while the
// tissue moves (the renderer adds its own highlights from the lighting).
//
//   otsu_threshold     eq 31: the threshold k of a 256-bin histogram that maximises the
//                      variance between the two regions, (P_s(k) g_T - g(k))^2 / (P_s(k) P_b(k))
//                      (P_s the probability below k, g(k) the cumulative grey sum, g_T the
//                      mean of the whole frame where the paper prints g_s: docs/decisions.md)
//   specular_mask      the spot region U_s: min(R, G, B) (a glint is bright in every channel,
//                      tissue is not) above the Otsu threshold and at least `min_level`
//   magnify_spots      U_s': every connected spot magnified 1.1x by bilinear interpolation
//                      about its centre of mass (the registration of the paper: the centres
//                      of mass of U_s and U_s' coincide), and grown by one pixel (the rim)
//   fill_region        the repair: the region filled inwards from the ring of pixels around
//                      it, each pixel the mean of its already known 8 neighbours
//   repair_specular    all of it on one frame
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "render/image.h"

namespace phyxel::render {

struct SpecularOptions {
  int min_level = 200;         // a spot's min(R, G, B) is above this too (0 ... 255)
  double max_fraction = 0.15;  // more of the frame than this is not spots: nothing repaired
  double magnify = 1.1;        // the paper's magnification of U_s
};

// Eq 31 over `histogram` (counts of grey levels 0 ... 255): the k maximising the between-class
// variance; pixels > k are the bright class. 0 for an empty or one-level histogram.
int otsu_threshold(const std::array<uint64_t, 256>& histogram);

// One byte per pixel, 1 where a specular spot is (row-major, image.width x image.height).
std::vector<uint8_t> specular_mask(const RgbaImage& image, const SpecularOptions& options = {});

// U_s' of `mask` (width x height): each 8-connected spot magnified `scale` times about its
// centre of mass, plus a one-pixel border.
std::vector<uint8_t> magnify_spots(const std::vector<uint8_t>& mask, uint32_t width,
                                   uint32_t height, double scale = 1.1);

// Fills the pixels of `region` (1 = to fill) from the pixels around it, ring by ring inwards.
// Pixels outside the region are left as they are. A region that covers the whole image is
// left alone.
void fill_region(RgbaImage& image, const std::vector<uint8_t>& region);

// specular_mask, magnify_spots, fill_region. Returns the number of pixels repaired.
size_t repair_specular(RgbaImage& image, const SpecularOptions& options = {});

}  // namespace phyxel::render
