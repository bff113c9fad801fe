// Frames drawn while the simulation goes on: FrameQueue records a frame and submits it without
// waiting; the next call (or drain()) waits for it, and the copy of its pixels out of the
// read-back buffer happens on the FrameSink's thread, which also writes the PNG and the video.
// The simulation thread pays for recording and submitting, not for the GPU's drawing or the
// copy of a 7–17 MB frame (docs/performance-log.md, "Frames off the simulation thread").
//
// A frame is two submissions (SplatRenderer::record_split): its deform pass on the solver's
// queue, the only part that reads the solver's buffers, then the rest on the context's frame
// queue (gpu::Context::frame_queue, a second queue of the compute family; the compute queue
// where there is none), waiting on a semaphore the deform signals. The solver's next passes
// wait for the deform pass alone; the frame's drawing runs beside them.
//
// One frame is in flight at a time, so that whatever the renderer reads (its surfels, tools,
// texture staging) may change once drain() has returned; two read-back slots let the sink
// copy one frame while the next is drawn. The solver's work that follows a frame on the same
// queue starts with a barrier, so it never writes what the frame still reads.
//
// Where the device has a transfer-only queue (a GPU's copy engines: gpu::Context::
// transfer_queue), the copy of the frame into its read-back slot is submitted there, waiting on
// a semaphore that the frame's drawing signals: the solver's next passes on the compute queue
// then run while the frame crosses the bus, instead of after it.
//
// Measurement switches (docs/performance-log.md, "The breast's frames: the drawing, not the
// pause"): $PHYXEL_FRAME_DRAW "0" submits the deform pass alone, $PHYXEL_FRAME_COPY "0" draws
// without the read-back copy; either way no frame reaches the sink.
#pragma once

#include <array>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "compute/recorder.h"
#include "render/splat_renderer.h"
#include "render/video_writer.h"

namespace phyxel::render {

class FrameQueue {
 public:
  // `renderer` and `sink` must outlive the queue and every frame it handed to the sink (the
  // sink copies out of the renderer's read-back buffers): destroy or finish the sink first.
  FrameQueue(gpu::Context& ctx, SplatRenderer& renderer, FrameSink& sink);
  ~FrameQueue();  // drain(), errors ignored
  FrameQueue(const FrameQueue&) = delete;
  FrameQueue& operator=(const FrameQueue&) = delete;

  // drain(), then records the frame of `inputs` into a free read-back slot and submits it.
  // Its pixels reach the sink as `name` (frame `video_index` of the video) at the next drain().
  void submit(const RenderInputs& inputs, const FrameSetup& setup, std::string name,
              int64_t video_index);
  // Completes the frame in flight, if any: waits for the GPU and hands its read-back slot to
  // the sink. Call before changing anything the renderer reads.
  void drain();
  bool in_flight() const { return pending_.has_value(); }
  // Whether frames are copied out on the device's transfer queue (see above).
  bool copies_on_transfer_queue() const { return copies_[0] != nullptr; }

 private:
  // Which slots the sink has not copied out yet (shared with the sink's jobs).
  struct Slots {
    std::mutex mutex;
    std::condition_variable freed;
    std::array<bool, SplatRenderer::kReadbackSlots> busy{};
    void release(uint32_t slot);  // busy[slot] = false, and wakes a waiting submit()
  };
  // Frees its slot when the last copy of the sink's job that holds it is destroyed: after the
  // copy ran, or unrun when the sink dropped the frame after a failure.
  struct SlotLease;
  struct Pending {
    uint32_t slot;
    std::string name;
    int64_t video_index;
  };
  void destroy_semaphores();  // and the recorders, which wait for their submissions first
  void record_and_submit(const RenderInputs& inputs, const FrameSetup& setup, uint32_t slot);

  SplatRenderer* renderer_;
  FrameSink* sink_;
  gpu::Context* ctx_;
  // Per slot the deform pass's recorder (compute queue), the drawing's (frame queue) and the
  // semaphore between them.
  std::array<std::unique_ptr<gpu::Recorder>, SplatRenderer::kReadbackSlots> deforms_;
  std::array<std::unique_ptr<gpu::Recorder>, SplatRenderer::kReadbackSlots> recorders_;
  std::array<VkSemaphore, SplatRenderer::kReadbackSlots> deformed_{};
  // With a transfer queue: per slot the copy's recorder and the semaphore the drawing signals.
  std::array<std::unique_ptr<gpu::Recorder>, SplatRenderer::kReadbackSlots> copies_;
  std::array<VkSemaphore, SplatRenderer::kReadbackSlots> drawn_{};
  std::shared_ptr<Slots> slots_ = std::make_shared<Slots>();
  std::optional<Pending> pending_;
  uint32_t next_ = 0;
  // $PHYXEL_FRAME_DRAW "0": the deform pass alone, nothing drawn or handed to the sink (to
  // time what the drawing costs a run; docs/performance-log.md).
  bool draws_ = true;
  // $PHYXEL_FRAME_COPY "0": drawn but not copied out (no read-back, nothing to the sink).
  bool reads_back_ = true;
};

}  // namespace phyxel::render
