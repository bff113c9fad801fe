// A per-pair array of the GPU solver (4 bytes a pair: the CSR neighbour index, the pair
// weights) held in two buffers, pairs [0, lo) and [lo, count), so that each part fits one
// storage-buffer binding (maxStorageBufferRange, 4 GiB on NVIDIA) and one allocation. A lattice
// reaches 4 GiB of pairs at about 41M phyxels; two parts take the solver to about 82M, past
// which the stress buffer (48 bytes a phyxel) exceeds one binding as well. Shaders read the two
// parts through compute/shaders/pair_buffers.glsl, which compares a pair with lo (a
// specialization constant of the pipelines, SolverKernels).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "compute/buffer.h"
#include "compute/pipeline.h"
#include "compute/recorder.h"

namespace phyxel::gpu {

// Pairs one part may hold on this device: the smaller of maxStorageBufferRange and
// maxMemoryAllocationSize, in 4-byte pairs. `bytes` (nonzero) lowers it, for tests that split
// small scenes.
uint64_t pairs_per_part(const Context& ctx, uint64_t bytes = 0);

class PairBuffer {
 public:
  PairBuffer() = default;
  // `count` pairs, the first min(count, per_part) in lo. Throws VulkanError (naming the device
  // and the sizes) when the rest does not fit one more part.
  PairBuffer(Context& ctx, uint64_t count, uint64_t per_part, const std::string& name);

  // The two bindings of pair_buffers.glsl: lo, and hi (lo again where every pair is in lo).
  BufferRef lo() const { return BufferRef(lo_); }
  BufferRef hi() const { return BufferRef(hi_ ? hi_ : lo_); }
  const Buffer& lo_buffer() const { return lo_; }
  const Buffer* hi_buffer() const { return hi_ ? &hi_ : nullptr; }

  // Records copies of all count() * 4 bytes, in pair order, to `dst` from `dst_offset` on, or
  // from `src` at `src_offset`.
  void record_copy_to(Recorder& rec, const Buffer& dst, VkDeviceSize dst_offset) const;
  void record_copy_from(Recorder& rec, const Buffer& src, VkDeviceSize src_offset);

  // Blocking download of every pair, in order.
  template <class T>
  std::vector<T> download(Context& ctx) const {
    static_assert(sizeof(T) == 4, "a pair entry is 4 bytes");
    std::vector<T> out(count_);
    download_bytes(ctx, out.data());
    return out;
  }

 private:
  void download_bytes(Context& ctx, void* out) const;

  Buffer lo_, hi_;
  uint64_t count_ = 0, lo_count_ = 0;
};

}  // namespace phyxel::gpu
