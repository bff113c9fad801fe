// A video texture that loops without a jump (the paper's section VI, step 2: "the image
// difference caused by the end point image hopping is dispersed"), by the weighted sum of
// frames of eq 32, f_k = sum_s W_s f_s: a clip of N frames loops over its first L = N - B
// frames, and each of the first B frames k is blended with frame L + k, the one that would
// have followed the end:
//
//   f'_k = w_k f_k + (1 - w_k) f_{L+k},   w_k = (k + 1) / (B + 1),   k = 0 ... B - 1
//
// so the loop's last frame f_{L-1} is followed by (nearly) f_L, its true successor, and the
// blend drifts back to the clip's own frames by frame B: the jump is spread over B frames.
#pragma once

#include <vector>

#include "render/image.h"

namespace phyxel::render {

// B as used for a clip of `frames` frames: at most half of them (0: no blending).
int loop_blend_frames(int frames, int blend);
// L = N - B, the frames in one loop.
int loop_length(int frames, int blend);
// w_k of eq 32 for frame k (1 for k >= B: the frame itself).
double loop_weight(int k, int blend);
// `head` (frame k of the clip) becomes f'_k; `tail` is frame L + k. Both of the same size.
void blend_loop_frame(RgbaImage& head, const RgbaImage& tail, int k, int blend);
// The whole loop of a clip in memory (for tests): L frames.
std::vector<RgbaImage> loop_clip(const std::vector<RgbaImage>& frames, int blend);

}  // namespace phyxel::render
