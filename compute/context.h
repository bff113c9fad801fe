// The Vulkan context: one instance, one chosen physical device, one logical device with one
// compute queue, its device function table, and the memory bookkeeping (allocation counter,
// check_fits). Everything else (buffers, pipelines, recorders) takes a Context&.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "compute/instance.h"

namespace phyxel::gpu {

// The PHYXEL_VALIDATION CMake option: whether a Context validates unless told otherwise.
bool validation_default();
// ContextOptions::descriptor_cache's default: on unless $PHYXEL_DESCRIPTOR_CACHE is "0" (to
// time the push-descriptor path against it).
bool descriptor_cache_default();

struct ContextOptions {
  // "gpu", "gpu:N" or part of a device name (see select_device in device_info.h).
  std::string device = "gpu";
  bool validation = validation_default();
  // Library to open; empty: $PHYXEL_VULKAN_LOADER, else libvulkan.so.1.
  std::string loader_path;
  // Use VK_KHR_push_descriptor where the device has it; false forces the descriptor-set path
  // (one pool per Recorder) that devices without the extension take.
  bool push_descriptors = true;
  // dispatch() binds a descriptor set its Recorder keeps per pipeline and binding list,
  // written on the first dispatch of that list and only bound after (compute/descriptor_cache.h),
  // instead of pushing or writing the descriptors at every dispatch.
  bool descriptor_cache = descriptor_cache_default();
  // How long Recorder::submit_and_wait waits for the GPU before giving up with an error; at
  // least 10 min on a CPU driver; $PHYXEL_GPU_TIMEOUT_S (seconds) overrides both (README).
  uint32_t fence_timeout_ms = 120000;
  // Open a queue of the device's transfer-only family where it has one (DeviceInfo), for
  // copies that may run beside the compute queue's work (a frame's read-back: FrameQueue).
  bool transfer_queue = true;
  // Open a second queue of the compute family where it has several, for frames drawn beside
  // the solver's work (FrameQueue).
  bool frame_queue = true;
};

class Context {
 public:
  explicit Context(const ContextOptions& options = {});
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  // Device-level entry points: ctx.fn().vkCmdDispatch(...).
  const DeviceFunctions& fn() const { return fn_; }
  VkDevice device() const { return device_; }
  VkPhysicalDevice physical_device() const { return physical_; }
  VkQueue queue() const { return queue_; }
  uint32_t queue_family() const { return info_.compute_queue_family; }
  // The transfer-only queue (ContextOptions::transfer_queue); VK_NULL_HANDLE where there is none.
  VkQueue transfer_queue() const { return transfer_queue_; }
  uint32_t transfer_queue_family() const {
    return transfer_queue_ != VK_NULL_HANDLE ? info_.transfer_queue_family : UINT32_MAX;
  }
  // The second queue of the compute family (ContextOptions::frame_queue); VK_NULL_HANDLE where
  // there is none.
  VkQueue frame_queue() const { return frame_queue_; }
  const DeviceInfo& info() const { return info_; }
  const Instance& instance() const { return *instance_; }
  const ContextOptions& options() const { return options_; }

  // Support actually enabled on this device.
  bool push_descriptors() const { return push_descriptors_; }
  bool descriptor_cache() const { return options_.descriptor_cache; }
  // Whether dispatch() pushes its descriptors (the extension on and no cache).
  bool pushes_descriptors() const { return push_descriptors_ && !options_.descriptor_cache; }
  bool memory_budget() const { return memory_budget_; }
  bool float64() const { return info_.float64; }
  bool int64() const { return info_.int64; }
  bool int64_atomics() const { return info_.int64_atomics; }
  bool timestamps() const { return info_.timestamps(); }

  // Null unless validation is on; see ValidationLog.
  std::shared_ptr<const ValidationLog> validation_log() const {
    return instance_->validation_log();
  }

  // Memory.
  const VkPhysicalDeviceMemoryProperties& memory_properties() const { return memory_; }
  uint32_t device_local_heap() const { return device_heap_; }
  uint64_t allocated_bytes() const { return allocated_.load(); }  // live, all intents
  void track_allocation(int64_t delta_bytes) { allocated_ += static_cast<uint64_t>(delta_bytes); }
  // Bytes that can still be allocated from the device-local heap: budget minus usage with
  // VK_EXT_memory_budget, else heap size minus what this context allocated.
  uint64_t available_device_memory() const;
  // Throws VulkanError (VK_ERROR_OUT_OF_DEVICE_MEMORY) naming the bytes needed and available
  // when `bytes` more device memory does not fit. Call it before allocating a scene.
  void check_fits(uint64_t bytes) const;

  // Test hooks of the GPU error paths (tests/vulkan/gpu_failure_test.cpp, tests/run), off
  // unless set. Read from the environment when the context is created; each costs a counter:
  //   PHYXEL_TEST_FAIL_ALLOC_AFTER=N        the first N buffer allocations of this context
  //                                         succeed, every later one fails as
  //                                         VK_ERROR_OUT_OF_DEVICE_MEMORY (Buffer's constructor).
  //   PHYXEL_TEST_FENCE_TIMEOUT_MS=N        ContextOptions::fence_timeout_ms is N (0: every wait
  //                                         for unfinished work times out at once).
  //   PHYXEL_TEST_DEVICE_LOST_AT_SUBSTEP=N  the GPU solver's submission that would run its N-th
  //                                         substep (counted from 1 over the solver's life) and
  //                                         every submission after it fail as
  //                                         VK_ERROR_DEVICE_LOST (Recorder::submit).
  // Buffer allocations made so far (counting those the hook failed).
  uint64_t allocation_count() const { return allocations_; }
  // Whether this allocation is to fail (the hook); counts it. Called by Buffer.
  bool test_allocation_fails() { return ++allocations_ > test_fail_alloc_after_; }
  // The hook, set in code: allocations after the next `n` fail; a negative `n` turns it off.
  void set_test_fail_allocation_after(int64_t n);
  // The GPU solver is about to submit work up to its substep `last` (counted from 1).
  void test_note_substeps(int64_t last) {
    if (last >= test_lost_at_substep_) test_device_lost_ = true;
  }
  // Whether submissions are to fail as VK_ERROR_DEVICE_LOST (the hook). Called by Recorder.
  bool test_device_lost() const { return test_device_lost_; }

  // Work the GPU did not finish in time (Recorder's fence timeout) may still run: from then on
  // nothing of this context is freed (buffers, pipelines, images, the device), since freeing
  // what in-flight work reads crashes (lavapipe runs it on threads of this process). The
  // process is ending with an error; the leak is its cost.
  void abandon() const { abandoned_.store(true); }
  bool abandoned() const { return abandoned_.load(); }

  // Debug name for RenderDoc and validation messages (VK_EXT_debug_utils; no-op without).
  void set_name(VkObjectType type, uint64_t handle, const std::string& name) const;

 private:
  void destroy();

  ContextOptions options_;
  std::unique_ptr<Instance> instance_;
  DeviceInfo info_;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  VkQueue transfer_queue_ = VK_NULL_HANDLE;
  VkQueue frame_queue_ = VK_NULL_HANDLE;
  DeviceFunctions fn_;
  VkPhysicalDeviceMemoryProperties memory_{};
  uint32_t device_heap_ = 0;
  bool push_descriptors_ = false;
  bool memory_budget_ = false;
  std::atomic<uint64_t> allocated_{0};
  uint64_t allocations_ = 0;
  uint64_t test_fail_alloc_after_ = UINT64_MAX;
  int64_t test_lost_at_substep_ = INT64_MAX;
  bool test_device_lost_ = false;
  mutable std::atomic<bool> abandoned_{false};
};

// "1.5 MiB", "12.0 GiB".
std::string format_bytes(uint64_t bytes);

}  // namespace phyxel::gpu
