#include "compute/buffer.h"

#include <atomic>
#include <cstring>
#include <utility>

#include "compute/recorder.h"

namespace phyxel::gpu {
namespace {

constexpr VkDeviceSize kMinAllocation = 16;

// The last serial given to a buffer (Buffer::serial).
std::atomic<uint64_t> last_serial{0};

// Index of the first type in `type_bits` that has all `required` flags, preferring those that
// also have all `preferred` flags and none of `avoided`.
uint32_t find_type(const VkPhysicalDeviceMemoryProperties& memory, uint32_t type_bits,
                   VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred,
                   VkMemoryPropertyFlags avoided) {
  uint32_t fallback = UINT32_MAX;
  for (uint32_t i = 0; i < memory.memoryTypeCount; ++i) {
    if ((type_bits & (1u << i)) == 0) continue;
    const VkMemoryPropertyFlags flags = memory.memoryTypes[i].propertyFlags;
    if ((flags & required) != required) continue;
    if ((flags & preferred) == preferred && (flags & avoided) == 0) return i;
    if (fallback == UINT32_MAX) fallback = i;
  }
  return fallback;
}

void check_range(const Buffer& buffer, VkDeviceSize bytes, VkDeviceSize offset, const char* what) {
  if (!buffer) throw VulkanError(std::string(what) + ": empty buffer");
  if (offset > buffer.size() || bytes > buffer.size() - offset) {
    throw VulkanError(std::string(what) + " of " + std::to_string(bytes) + " bytes at offset " +
                      std::to_string(offset) + " does not fit buffer '" + buffer.name() + "' of " +
                      std::to_string(buffer.size()) + " bytes");
  }
}

// One line: the device, the buffer, its size, the cause and what to do.
VulkanError allocation_failure(const Context& ctx, const std::string& name, MemoryIntent intent,
                               VkDeviceSize size, VkResult result) {
  const bool host = result == VK_ERROR_OUT_OF_HOST_MEMORY;
  return VulkanError(
      std::string(host ? "out of host memory" : "out of GPU memory") + " on " + ctx.info().name +
          ": allocating " + format_bytes(size) + " of " + intent_name(intent) +
          " memory for buffer '" + name + "' failed with " + vk_result_name(result) + " (" +
          format_bytes(ctx.allocated_bytes()) +
          " already allocated); use a larger spacing or a smaller scene, close other programs "
          "using the GPU, or run with --device cpu",
      result);
}

}  // namespace

const char* intent_name(MemoryIntent intent) {
  switch (intent) {
    case MemoryIntent::Device:
      return "device";
    case MemoryIntent::Upload:
      return "upload";
    case MemoryIntent::Readback:
      return "readback";
  }
  return "?";
}

uint32_t choose_memory_type(const VkPhysicalDeviceMemoryProperties& memory, uint32_t type_bits,
                            MemoryIntent intent) {
  constexpr VkMemoryPropertyFlags kLocal = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
  constexpr VkMemoryPropertyFlags kVisible = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
  constexpr VkMemoryPropertyFlags kCoherent = VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  constexpr VkMemoryPropertyFlags kCached = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
  switch (intent) {
    case MemoryIntent::Device:
      // Device-local if at all possible; prefer types the host cannot see (the real VRAM,
      // not the small BAR window), but take any type on devices that only have such.
      {
        const uint32_t t = find_type(memory, type_bits, kLocal, 0, kVisible);
        return t != UINT32_MAX ? t : find_type(memory, type_bits, 0, 0, 0);
      }
    case MemoryIntent::Upload:
      // Write-combined system memory: host-visible and coherent, not device-local (leave the
      // BAR window alone), not cached.
      return find_type(memory, type_bits, kVisible | kCoherent, 0, kLocal | kCached);
    case MemoryIntent::Readback: {
      const uint32_t t = find_type(memory, type_bits, kVisible | kCached, kCoherent, 0);
      return t != UINT32_MAX ? t : find_type(memory, type_bits, kVisible, kCoherent, 0);
    }
  }
  return UINT32_MAX;
}

Buffer::Buffer(Context& ctx, VkDeviceSize size, MemoryIntent intent, const std::string& name,
               VkBufferUsageFlags extra_usage, bool with_transfer_queue)
    : ctx_(&ctx), size_(size), intent_(intent), name_(name) {
  const DeviceInfo& info = ctx.info();
  if (info.max_allocation_size != 0 && size > info.max_allocation_size) {
    throw VulkanError("buffer '" + name + "' needs " + format_bytes(size) + " but " + info.name +
                          " allocates at most " + format_bytes(info.max_allocation_size) +
                          " at once; use a smaller scene, or --device cpu",
                      VK_ERROR_OUT_OF_DEVICE_MEMORY);
  }
  if (intent == MemoryIntent::Device) ctx.check_fits(size);
  const DeviceFunctions& fn = ctx.fn();
  auto create = vk_struct<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
  create.size = size < kMinAllocation ? kMinAllocation : size;
  create.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                 VK_BUFFER_USAGE_TRANSFER_DST_BIT | extra_usage;
  create.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  const uint32_t families[2] = {ctx.queue_family(), ctx.transfer_queue_family()};
  if (with_transfer_queue && families[1] != UINT32_MAX) {
    create.sharingMode = VK_SHARING_MODE_CONCURRENT;
    create.queueFamilyIndexCount = 2;
    create.pQueueFamilyIndices = families;
  }
  VK_CHECK(fn.vkCreateBuffer(ctx.device(), &create, nullptr, &buffer_));
  try {
    VkMemoryRequirements needs{};
    fn.vkGetBufferMemoryRequirements(ctx.device(), buffer_, &needs);
    const uint32_t type = choose_memory_type(ctx.memory_properties(), needs.memoryTypeBits, intent);
    if (type == UINT32_MAX) {
      throw VulkanError(
          "no memory type for a " + std::string(intent_name(intent)) + " buffer on " + info.name,
          VK_ERROR_FEATURE_NOT_PRESENT);
    }
    auto alloc = vk_struct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
    alloc.allocationSize = needs.size;
    alloc.memoryTypeIndex = type;
    // The allocation test hook (context.h) fails it as a full device would.
    const VkResult allocated = ctx.test_allocation_fails()
                                   ? VK_ERROR_OUT_OF_DEVICE_MEMORY
                                   : fn.vkAllocateMemory(ctx.device(), &alloc, nullptr, &memory_);
    if (allocated != VK_SUCCESS) throw allocation_failure(ctx, name, intent, needs.size, allocated);
    allocated_ = needs.size;
    ctx.track_allocation(static_cast<int64_t>(allocated_));
    VK_CHECK(fn.vkBindBufferMemory(ctx.device(), buffer_, memory_, 0));
    const VkMemoryPropertyFlags flags = ctx.memory_properties().memoryTypes[type].propertyFlags;
    coherent_ = (flags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT) != 0;
    if (intent != MemoryIntent::Device) {
      VK_CHECK(fn.vkMapMemory(ctx.device(), memory_, 0, VK_WHOLE_SIZE, 0, &mapped_));
    }
    ctx.set_name(VK_OBJECT_TYPE_BUFFER, reinterpret_cast<uint64_t>(buffer_), name);
    ctx.set_name(VK_OBJECT_TYPE_DEVICE_MEMORY, reinterpret_cast<uint64_t>(memory_), name);
    serial_ = ++last_serial;
  } catch (...) {
    reset();
    throw;
  }
}

Buffer::~Buffer() {
  reset();
}

Buffer::Buffer(Buffer&& other) noexcept {
  *this = std::move(other);
}

Buffer& Buffer::operator=(Buffer&& other) noexcept {
  if (this != &other) {
    reset();
    ctx_ = std::exchange(other.ctx_, nullptr);
    buffer_ = std::exchange(other.buffer_, VK_NULL_HANDLE);
    memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
    size_ = std::exchange(other.size_, 0);
    allocated_ = std::exchange(other.allocated_, 0);
    intent_ = other.intent_;
    mapped_ = std::exchange(other.mapped_, nullptr);
    coherent_ = other.coherent_;
    name_ = std::move(other.name_);
    serial_ = std::exchange(other.serial_, 0);
  }
  return *this;
}

void Buffer::reset() {
  if (ctx_ == nullptr) return;
  const DeviceFunctions& fn = ctx_->fn();
  const bool in_use = ctx_->abandoned();  // unfinished work may read it: leak it
  if (buffer_ != VK_NULL_HANDLE && !in_use) fn.vkDestroyBuffer(ctx_->device(), buffer_, nullptr);
  if (memory_ != VK_NULL_HANDLE && !in_use) {
    // Freeing memory unmaps it.
    fn.vkFreeMemory(ctx_->device(), memory_, nullptr);
    ctx_->track_allocation(-static_cast<int64_t>(allocated_));
  }
  buffer_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
  mapped_ = nullptr;
  size_ = 0;
  allocated_ = 0;
  serial_ = 0;
  ctx_ = nullptr;
}

void Buffer::invalidate() const {
  if (mapped_ == nullptr || coherent_) return;
  auto range = vk_struct<VkMappedMemoryRange>(VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE);
  range.memory = memory_;
  range.offset = 0;
  range.size = VK_WHOLE_SIZE;
  VK_CHECK(ctx_->fn().vkInvalidateMappedMemoryRanges(ctx_->device(), 1, &range));
}

void upload(Context& ctx, const Buffer& dst, const void* data, VkDeviceSize bytes,
            VkDeviceSize dst_offset) {
  check_range(dst, bytes, dst_offset, "upload");
  if (bytes == 0) return;
  if (dst.intent() == MemoryIntent::Upload) {
    // Host-coherent by construction: the next vkQueueSubmit makes the write visible.
    std::memcpy(static_cast<char*>(dst.mapped()) + dst_offset, data, bytes);
    return;
  }
  Buffer staging(ctx, bytes, MemoryIntent::Upload, "upload staging for " + dst.name());
  std::memcpy(staging.mapped(), data, bytes);
  Recorder rec(ctx, "upload");
  rec.barrier();  // after the work submitted before on the queue (a frame still reading dst)
  rec.copy(staging, dst, bytes, 0, dst_offset);
  rec.submit_and_wait();
}

void download(Context& ctx, const Buffer& src, void* data, VkDeviceSize bytes,
              VkDeviceSize src_offset) {
  check_range(src, bytes, src_offset, "download");
  if (bytes == 0) return;
  if (src.intent() == MemoryIntent::Readback) {
    src.invalidate();
    std::memcpy(data, static_cast<const char*>(src.mapped()) + src_offset, bytes);
    return;
  }
  Buffer staging(ctx, bytes, MemoryIntent::Readback, "download staging for " + src.name());
  Recorder rec(ctx, "download");
  rec.barrier();  // after the work submitted before on the queue (its writes of src)
  rec.copy(src, staging, bytes, src_offset, 0);
  rec.submit_and_wait();
  staging.invalidate();
  std::memcpy(data, staging.mapped(), bytes);
}

}  // namespace phyxel::gpu
