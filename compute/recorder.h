// Command recording: many dispatches, copies and barriers go into one command buffer, which is
// submitted once and waited for with a fence. A Recorder is recording from construction on and
// again after each wait(), so it can be reused step after step.
//
//   Recorder rec(ctx, "step");
//   dispatch(rec, forces, push, {x, f}, n);
//   rec.barrier();                      // forces written → integrate reads them
//   dispatch(rec, integrate, push2, {x, v, f}, n);
//   rec.submit_and_wait();
//
// Passes are not separated automatically: put rec.barrier() between a pass that writes a
// buffer and one that reads or writes it (the tests run with synchronization validation).
#pragma once

#include <string>
#include <vector>

#include "compute/buffer.h"
#include "compute/descriptor_cache.h"

namespace phyxel::gpu {

// Which of the context's queues a Recorder submits to: the compute queue (everything), or the
// transfer-only queue (Context::transfer_queue; copies and fills alone, its barriers on the
// transfer stage).
// Compute: the context's queue; Frame: its frame queue where it has one, else the compute
// queue; Transfer: its transfer queue (required).
enum class QueueRole { Compute, Frame, Transfer };

class Recorder {
 public:
  explicit Recorder(Context& ctx, const std::string& name = "phyxel commands",
                    QueueRole role = QueueRole::Compute);
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  Context& context() const { return *ctx_; }
  VkCommandBuffer cmd() const { return cmd_; }
  uint32_t dispatch_count() const { return dispatches_; }  // since the last wait()
  bool recording() const { return recording_; }            // false between submit() and wait()

  // Compute-shader and transfer writes before it are visible to compute-shader and transfer
  // reads and writes after it (one global memory barrier: the right tool for buffers).
  void barrier();
  // barrier() that also makes compute-shader writes visible to indirect dispatch arguments.
  void indirect_barrier();
  // Compute shader writes before compute shader reads and writes only: between two
  // dispatches with no transfer command on either side.
  void compute_barrier();
  void barrier(VkPipelineStageFlags src_stages, VkAccessFlags src_access,
               VkPipelineStageFlags dst_stages, VkAccessFlags dst_access);

  // vkCmdCopyBuffer; bytes = VK_WHOLE_SIZE copies all of src from src_offset.
  void copy(const Buffer& src, const Buffer& dst, VkDeviceSize bytes = VK_WHOLE_SIZE,
            VkDeviceSize src_offset = 0, VkDeviceSize dst_offset = 0);
  // vkCmdFillBuffer with a 32-bit pattern (offset and size in multiples of 4).
  void fill(const Buffer& dst, uint32_t value, VkDeviceSize offset = 0,
            VkDeviceSize bytes = VK_WHOLE_SIZE);

  // Ends the command buffer (with a barrier that makes GPU writes visible to the host) and
  // submits it. Only one submission is in flight per Recorder. `wait_for`: a semaphore another
  // submission signals, waited for before this one's commands run; `signal`: signalled when
  // this one's are done (binary semaphores, for work handed between queues).
  void submit(VkSemaphore wait_for = VK_NULL_HANDLE, VkSemaphore signal = VK_NULL_HANDLE);
  // Waits for the submission (ContextOptions::fence_timeout_ms); a timeout or a lost device
  // throws VulkanError. Then recording starts again.
  void wait();
  void submit_and_wait() {
    submit();
    wait();
  }

  // For dispatch() without the cache on devices without push descriptors: a set from this
  // recorder's pools, valid until the next wait().
  VkDescriptorSet allocate_descriptor_set(VkDescriptorSetLayout layout) {
    return per_dispatch_.allocate(layout);
  }
  // For dispatch() with ContextOptions::descriptor_cache: the sets this recorder's commands
  // bind, kept across submissions (dropped after a wait() once kCachedSets are kept).
  DescriptorSetCache& descriptor_cache() { return cache_; }
  static constexpr size_t kCachedSets = 1024;
  void count_dispatch() { ++dispatches_; }

 private:
  void begin();

  Context* ctx_;
  std::string name_;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  DescriptorPools per_dispatch_;
  DescriptorSetCache cache_;
  uint32_t dispatches_ = 0;
  bool recording_ = false;
  bool pending_ = false;
  QueueRole role_ = QueueRole::Compute;
  VkQueue queue_ = VK_NULL_HANDLE;
  VkPipelineStageFlags stages_ = 0;  // the stages this queue's barriers name
};

}  // namespace phyxel::gpu
