#include "render/frame_queue.h"

#include <exception>
#include <utility>

#include "compute/env.h"
#include "compute/vk_check.h"

namespace phyxel::render {

void FrameQueue::Slots::release(uint32_t slot) {
  {
    std::lock_guard lock(mutex);
    busy[slot] = false;
  }
  freed.notify_all();
}

struct FrameQueue::SlotLease {
  std::shared_ptr<Slots> slots;
  uint32_t slot;
  SlotLease(std::shared_ptr<Slots> s, uint32_t k) : slots(std::move(s)), slot(k) {}
  SlotLease(const SlotLease&) = delete;
  SlotLease& operator=(const SlotLease&) = delete;
  ~SlotLease() { slots->release(slot); }
};

FrameQueue::FrameQueue(gpu::Context& ctx, SplatRenderer& renderer, FrameSink& sink)
    : renderer_(&renderer), sink_(&sink), ctx_(&ctx) {
  draws_ = gpu::env_switch("PHYXEL_FRAME_DRAW");
  reads_back_ = gpu::env_switch("PHYXEL_FRAME_COPY");
  if (!reads_back_) renderer.set_readback(false);
  const bool transfer = ctx.transfer_queue() != VK_NULL_HANDLE && reads_back_;
  auto semaphore = [&ctx](VkSemaphore& s) {
    auto info = vk_struct<VkSemaphoreCreateInfo>(VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO);
    VK_CHECK(ctx.fn().vkCreateSemaphore(ctx.device(), &info, nullptr, &s));
  };
  try {
    for (uint32_t k = 0; k < recorders_.size(); ++k) {
      std::string name = "frame ";
      name += std::to_string(k);
      deforms_[k] = std::make_unique<gpu::Recorder>(ctx, name + " deform");
      recorders_[k] = std::make_unique<gpu::Recorder>(ctx, name, gpu::QueueRole::Frame);
      semaphore(deformed_[k]);
      if (!transfer) continue;
      copies_[k] =
          std::make_unique<gpu::Recorder>(ctx, name + " read-back copy", gpu::QueueRole::Transfer);
      semaphore(drawn_[k]);
    }
  } catch (...) {
    destroy_semaphores();
    throw;
  }
}

FrameQueue::~FrameQueue() {
  try {
    drain();
  } catch (const std::exception&) {  // NOLINT(bugprone-empty-catch): a destructor stays quiet
  }
  destroy_semaphores();
}

void FrameQueue::destroy_semaphores() {
  // Only once nothing waits on or signals them: drain() waited for both submissions, and a
  // failed one never reached the queue or is waited for by the recorders' destructors first.
  for (auto& c : copies_) c.reset();
  for (auto& r : recorders_) r.reset();
  for (auto& r : deforms_) r.reset();
  for (auto* semaphores : {&drawn_, &deformed_}) {
    for (VkSemaphore& s : *semaphores) {
      if (s != VK_NULL_HANDLE && !ctx_->abandoned())
        ctx_->fn().vkDestroySemaphore(ctx_->device(), s, nullptr);
      s = VK_NULL_HANDLE;
    }
  }
}

void FrameQueue::drain() {
  if (!pending_) return;
  const Pending frame = std::move(*pending_);
  pending_.reset();
  try {
    deforms_[frame.slot]->wait();
    if (draws_) recorders_[frame.slot]->wait();
    if (draws_ && copies_[frame.slot]) copies_[frame.slot]->wait();
  } catch (...) {
    slots_->release(frame.slot);
    throw;
  }
  if (!draws_ || !reads_back_) {  // measurement switches: no pixels
    slots_->release(frame.slot);
    return;
  }
  auto lease = std::make_shared<SlotLease>(slots_, frame.slot);
  SplatRenderer* renderer = renderer_;
  const uint32_t slot = frame.slot;
  sink_->push(
      frame.name, [renderer, slot, lease] { return renderer->read_frame(slot); },
      frame.video_index);
}

void FrameQueue::submit(const RenderInputs& inputs, const FrameSetup& setup, std::string name,
                        int64_t video_index) {
  drain();
  const uint32_t slot = next_;
  next_ = (next_ + 1) % SplatRenderer::kReadbackSlots;
  {
    // The sink copies frames in order: the slot's last frame is at most one behind.
    std::unique_lock lock(slots_->mutex);
    slots_->freed.wait(lock, [&] { return !slots_->busy[slot]; });
    slots_->busy[slot] = true;
  }
  try {
    record_and_submit(inputs, setup, slot);
  } catch (...) {
    slots_->release(slot);
    throw;
  }
  pending_ = Pending{slot, std::move(name), video_index};
}

// The deform pass, then the drawing after it, then (with a transfer queue) the copy after that.
// A submission that fails leaves those before it waited for, so that their recorders record
// again (the error, a lost device, is the one to report).
void FrameQueue::record_and_submit(const RenderInputs& inputs, const FrameSetup& setup,
                                   uint32_t slot) {
  gpu::Recorder& deform = *deforms_[slot];
  gpu::Recorder& rec = *recorders_[slot];
  gpu::Recorder* copy = copies_[slot].get();
  if (!draws_) {
    renderer_->record_deform(deform, inputs);
    deform.submit();
    return;
  }
  renderer_->record_split(deform, rec, inputs, setup, slot, copy);
  std::vector<gpu::Recorder*> submitted;
  try {
    deform.submit(VK_NULL_HANDLE, deformed_[slot]);
    submitted.push_back(&deform);
    rec.submit(deformed_[slot], copy != nullptr ? drawn_[slot] : VK_NULL_HANDLE);
    submitted.push_back(&rec);
    if (copy != nullptr) copy->submit(drawn_[slot]);
  } catch (...) {
    for (gpu::Recorder* r : submitted) {
      try {
        r->wait();
      } catch (...) {  // NOLINT(bugprone-empty-catch)
      }
    }
    throw;
  }
}

}  // namespace phyxel::render
