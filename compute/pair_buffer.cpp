#include "compute/pair_buffer.h"

#include <algorithm>

#include "compute/vk_check.h"

namespace phyxel::gpu {

uint64_t pairs_per_part(const Context& ctx, uint64_t bytes) {
  const DeviceInfo& info = ctx.info();
  uint64_t limit = info.max_storage_buffer_range;
  if (info.max_allocation_size != 0) limit = std::min(limit, info.max_allocation_size);
  if (bytes != 0) limit = std::min(limit, bytes);
  // At least 64 pairs: a part that holds none would split nothing.
  return std::max<uint64_t>(limit / 4, 64);
}

PairBuffer::PairBuffer(Context& ctx, uint64_t count, uint64_t per_part, const std::string& name)
    : count_(count), lo_count_(std::min(count, per_part)) {
  if (count - lo_count_ > per_part) {
    throw VulkanError("the scene has " + std::to_string(count) + " neighbour pairs, but " +
                          ctx.info().name + " binds at most " + std::to_string(per_part) +
                          " of them (" + format_bytes(per_part * 4) +
                          ", maxStorageBufferRange) in each of the two parts of the " + name +
                          "; use a smaller scene or support radius, or --device cpu",
                      VK_ERROR_OUT_OF_DEVICE_MEMORY);
  }
  lo_ = Buffer(ctx, lo_count_ * 4, MemoryIntent::Device, name);
  if (count > lo_count_)
    hi_ = Buffer(ctx, (count - lo_count_) * 4, MemoryIntent::Device, name + " (hi)");
}

void PairBuffer::record_copy_to(Recorder& rec, const Buffer& dst, VkDeviceSize dst_offset) const {
  if (lo_count_ > 0) rec.copy(lo_, dst, lo_count_ * 4, 0, dst_offset);
  if (hi_) rec.copy(hi_, dst, (count_ - lo_count_) * 4, 0, dst_offset + lo_count_ * 4);
}

void PairBuffer::record_copy_from(Recorder& rec, const Buffer& src, VkDeviceSize src_offset) {
  if (lo_count_ > 0) rec.copy(src, lo_, lo_count_ * 4, src_offset, 0);
  if (hi_) rec.copy(src, hi_, (count_ - lo_count_) * 4, src_offset + lo_count_ * 4, 0);
}

void PairBuffer::download_bytes(Context& ctx, void* out) const {
  auto* bytes = static_cast<unsigned char*>(out);
  if (lo_count_ > 0) gpu::download(ctx, lo_, bytes, lo_count_ * 4);
  if (hi_) gpu::download(ctx, hi_, bytes + lo_count_ * 4, (count_ - lo_count_) * 4);
}

}  // namespace phyxel::gpu
