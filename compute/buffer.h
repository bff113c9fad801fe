// GPU buffers chosen by intent (Granite style) rather than by raw memory flags, and blocking
// upload/download helpers that go through a staging buffer when needed.
//
//   Device    device-local; the solver's state. Not mapped.
//   Upload    host-visible, coherent, persistently mapped; CPU writes, GPU reads.
//   Readback  host-visible (cached where possible), persistently mapped; GPU writes, CPU reads.
//
// Every buffer can be a storage buffer and a copy source and destination. One allocation per
// buffer: Phyxel has few, large buffers (see compute/README.md).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "compute/context.h"

namespace phyxel::gpu {

enum class MemoryIntent { Device, Upload, Readback };

const char* intent_name(MemoryIntent intent);

// The memory type for `intent` among `type_bits` (from vkGetBufferMemoryRequirements), or
// UINT32_MAX when none qualifies.
uint32_t choose_memory_type(const VkPhysicalDeviceMemoryProperties& memory, uint32_t type_bits,
                            MemoryIntent intent);

class Buffer {
 public:
  Buffer() = default;
  // Device buffers are checked with Context::check_fits before allocating. A size of 0 is
  // allowed (an empty array): the buffer then holds a few bytes so it can still be bound.
  // `with_transfer_queue`: the buffer is also used on the context's transfer queue, where it
  // has one (shared by both queue families, no ownership transfers).
  Buffer(Context& ctx, VkDeviceSize size, MemoryIntent intent, const std::string& name,
         VkBufferUsageFlags extra_usage = 0, bool with_transfer_queue = false);
  ~Buffer();
  Buffer(Buffer&& other) noexcept;
  Buffer& operator=(Buffer&& other) noexcept;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;

  void reset();  // destroys the buffer now; the Buffer becomes empty

  explicit operator bool() const { return buffer_ != VK_NULL_HANDLE; }
  VkBuffer handle() const { return buffer_; }
  VkDeviceSize size() const { return size_; }  // as requested
  MemoryIntent intent() const { return intent_; }
  const std::string& name() const { return name_; }
  // Unique to this VkBuffer among all buffers of the process, never reused (a destroyed
  // buffer's handle value may be); 0 when empty. Moves carry it. Keys the Recorder's
  // descriptor sets.
  uint64_t serial() const { return serial_; }
  // Mapped pointer of Upload and Readback buffers; null for Device buffers.
  void* mapped() const { return mapped_; }
  // Makes GPU writes visible to mapped() on non-coherent memory (a no-op on coherent memory).
  // download() calls it; call it yourself before reading mapped() of a Readback buffer.
  void invalidate() const;

 private:
  Context* ctx_ = nullptr;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
  VkDeviceSize allocated_ = 0;
  MemoryIntent intent_ = MemoryIntent::Device;
  void* mapped_ = nullptr;
  bool coherent_ = true;
  std::string name_;
  uint64_t serial_ = 0;
};

// Blocking copies between host memory and a buffer (a one-off submit through a staging buffer
// when `buffer` is not mapped). For setup and output, not for per-step traffic: record copies
// into the step's Recorder instead.
void upload(Context& ctx, const Buffer& dst, const void* data, VkDeviceSize bytes,
            VkDeviceSize dst_offset = 0);
void download(Context& ctx, const Buffer& src, void* data, VkDeviceSize bytes,
              VkDeviceSize src_offset = 0);

template <class T>
void upload(Context& ctx, const Buffer& dst, const std::vector<T>& data,
            VkDeviceSize dst_offset = 0) {
  upload(ctx, dst, data.data(), data.size() * sizeof(T), dst_offset);
}

template <class T>
std::vector<T> download(Context& ctx, const Buffer& src, size_t count,
                        VkDeviceSize src_offset = 0) {
  std::vector<T> out(count);
  download(ctx, src, out.data(), count * sizeof(T), src_offset);
  return out;
}

}  // namespace phyxel::gpu
