#include "compute/recorder.h"

#include <cstdint>
#include <stdexcept>

namespace phyxel::gpu {
namespace {

constexpr VkPipelineStageFlags kGpuStages =
    VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;

}  // namespace

Recorder::Recorder(Context& ctx, const std::string& name, QueueRole role)
    : ctx_(&ctx), name_(name), per_dispatch_(ctx), cache_(ctx), role_(role) {
  const bool transfer = role == QueueRole::Transfer;
  if (transfer && ctx.transfer_queue() == VK_NULL_HANDLE)
    throw std::logic_error("Recorder '" + name + "': " + ctx.info().name +
                           " has no transfer queue open");
  queue_ = transfer ? ctx.transfer_queue() : ctx.queue();
  if (role == QueueRole::Frame && ctx.frame_queue() != VK_NULL_HANDLE) queue_ = ctx.frame_queue();
  stages_ = transfer ? VkPipelineStageFlags{VK_PIPELINE_STAGE_TRANSFER_BIT} : kGpuStages;
  const DeviceFunctions& fn = ctx.fn();
  auto pool = vk_struct<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
  pool.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
  pool.queueFamilyIndex = transfer ? ctx.transfer_queue_family() : ctx.queue_family();
  VK_CHECK(fn.vkCreateCommandPool(ctx.device(), &pool, nullptr, &pool_));
  try {
    auto alloc =
        vk_struct<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
    alloc.commandPool = pool_;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    VK_CHECK(fn.vkAllocateCommandBuffers(ctx.device(), &alloc, &cmd_));
    auto fence = vk_struct<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
    VK_CHECK(fn.vkCreateFence(ctx.device(), &fence, nullptr, &fence_));
    ctx.set_name(VK_OBJECT_TYPE_COMMAND_BUFFER, reinterpret_cast<uint64_t>(cmd_), name);
    ctx.set_name(VK_OBJECT_TYPE_FENCE, reinterpret_cast<uint64_t>(fence_), name);
    begin();
  } catch (...) {
    if (fence_ != VK_NULL_HANDLE) fn.vkDestroyFence(ctx.device(), fence_, nullptr);
    fn.vkDestroyCommandPool(ctx.device(), pool_, nullptr);
    throw;
  }
}

Recorder::~Recorder() {
  const DeviceFunctions& fn = ctx_->fn();
  if (pending_) {
    // Never free what the GPU may still use: if it does not finish in time (hung device),
    // leak the pool rather than hang or free in-flight commands, and so does the context.
    const uint64_t timeout_ns = uint64_t{ctx_->options().fence_timeout_ms} * 1000000u;
    if (ctx_->abandoned() ||
        fn.vkWaitForFences(ctx_->device(), 1, &fence_, VK_TRUE, timeout_ns) == VK_TIMEOUT) {
      ctx_->abandon();
      per_dispatch_.abandon();
      cache_.abandon();
      return;
    }
  }
  fn.vkDestroyFence(ctx_->device(), fence_, nullptr);
  fn.vkDestroyCommandPool(ctx_->device(), pool_, nullptr);
}

void Recorder::begin() {
  auto info = vk_struct<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
  info.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(ctx_->fn().vkBeginCommandBuffer(cmd_, &info));
  recording_ = true;
  dispatches_ = 0;
}

void Recorder::barrier() {
  if (role_ == QueueRole::Transfer) {
    barrier(stages_, VK_ACCESS_TRANSFER_WRITE_BIT, stages_,
            VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT);
    return;
  }
  barrier(kGpuStages, VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT, kGpuStages,
          VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
              VK_ACCESS_TRANSFER_WRITE_BIT);
}

void Recorder::compute_barrier() {
  barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
          VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
          VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

void Recorder::indirect_barrier() {
  barrier(kGpuStages, VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT,
          kGpuStages | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT,
          VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
              VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_INDIRECT_COMMAND_READ_BIT);
}

void Recorder::barrier(VkPipelineStageFlags src_stages, VkAccessFlags src_access,
                       VkPipelineStageFlags dst_stages, VkAccessFlags dst_access) {
  if (!recording_) throw VulkanError("Recorder '" + name_ + "': barrier() while not recording");
  auto memory = vk_struct<VkMemoryBarrier>(VK_STRUCTURE_TYPE_MEMORY_BARRIER);
  memory.srcAccessMask = src_access;
  memory.dstAccessMask = dst_access;
  ctx_->fn().vkCmdPipelineBarrier(cmd_, src_stages, dst_stages, 0, 1, &memory, 0, nullptr, 0,
                                  nullptr);
}

void Recorder::copy(const Buffer& src, const Buffer& dst, VkDeviceSize bytes,
                    VkDeviceSize src_offset, VkDeviceSize dst_offset) {
  if (!recording_) throw VulkanError("Recorder '" + name_ + "': copy() while not recording");
  if (bytes == VK_WHOLE_SIZE) bytes = src.size() > src_offset ? src.size() - src_offset : 0;
  if (src_offset + bytes > src.size() || dst_offset + bytes > dst.size()) {
    throw VulkanError("copy of " + std::to_string(bytes) + " bytes from '" + src.name() + "' to '" +
                      dst.name() + "' runs past the end of a buffer");
  }
  if (bytes == 0) return;
  VkBufferCopy region{src_offset, dst_offset, bytes};
  ctx_->fn().vkCmdCopyBuffer(cmd_, src.handle(), dst.handle(), 1, &region);
}

void Recorder::fill(const Buffer& dst, uint32_t value, VkDeviceSize offset, VkDeviceSize bytes) {
  if (!recording_) throw VulkanError("Recorder '" + name_ + "': fill() while not recording");
  if (bytes == VK_WHOLE_SIZE) bytes = dst.size() > offset ? dst.size() - offset : 0;
  if (offset % 4 != 0 || bytes % 4 != 0 || offset + bytes > dst.size()) {
    throw VulkanError("fill of '" + dst.name() + "': offset " + std::to_string(offset) +
                      " and size " + std::to_string(bytes) +
                      " must be multiples of 4 inside the buffer");
  }
  if (bytes == 0) return;
  ctx_->fn().vkCmdFillBuffer(cmd_, dst.handle(), offset, bytes, value);
}

void Recorder::submit(VkSemaphore wait_for, VkSemaphore signal) {
  if (!recording_) throw VulkanError("Recorder '" + name_ + "': submit() while not recording");
  const DeviceFunctions& fn = ctx_->fn();
  // GPU writes → host reads of mapped Readback buffers after the fence wait.
  const VkAccessFlags writes = role_ == QueueRole::Transfer
                                   ? VkAccessFlags{VK_ACCESS_TRANSFER_WRITE_BIT}
                                   : VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  barrier(stages_, writes, VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
  recording_ = false;
  VK_CHECK(fn.vkEndCommandBuffer(cmd_));
  auto submit = vk_struct<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd_;
  const VkPipelineStageFlags wait_stages = stages_;
  if (wait_for != VK_NULL_HANDLE) {
    submit.waitSemaphoreCount = 1;
    submit.pWaitSemaphores = &wait_for;
    submit.pWaitDstStageMask = &wait_stages;
  }
  if (signal != VK_NULL_HANDLE) {
    submit.signalSemaphoreCount = 1;
    submit.pSignalSemaphores = &signal;
  }
  // The device-loss test hook (context.h) fails the submission as a lost device would.
  VK_CHECK(ctx_->test_device_lost() ? VK_ERROR_DEVICE_LOST
                                    : fn.vkQueueSubmit(queue_, 1, &submit, fence_));
  pending_ = true;
}

void Recorder::wait() {
  if (!pending_) throw VulkanError("Recorder '" + name_ + "': wait() without submit()");
  const DeviceFunctions& fn = ctx_->fn();
  const uint64_t timeout_ns = uint64_t{ctx_->options().fence_timeout_ms} * 1000000u;
  const VkResult waited = fn.vkWaitForFences(ctx_->device(), 1, &fence_, VK_TRUE, timeout_ns);
  if (waited == VK_TIMEOUT) {
    ctx_->abandon();
    throw VulkanError("the GPU did not finish '" + name_ + "' within " +
                          std::to_string(ctx_->options().fence_timeout_ms) +
                          " ms (hung or far too much work per submit); try a smaller scene, "
                          "fewer steps per submit, --device cpu, or a longer wait "
                          "(PHYXEL_GPU_TIMEOUT_S)",
                      VK_TIMEOUT);
  }
  VK_CHECK(waited);
  pending_ = false;
  VK_CHECK(fn.vkResetFences(ctx_->device(), 1, &fence_));
  VK_CHECK(fn.vkResetCommandPool(ctx_->device(), pool_, 0));
  per_dispatch_.reset();
  cache_.trim(kCachedSets);
  begin();
}

}  // namespace phyxel::gpu
