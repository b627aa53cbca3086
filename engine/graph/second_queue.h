// Runs of a graph on the device's second queue (Context::placement_queue()) beside the frames,
// ordered against them by two timelines, never by a wait on the host. Run k is recorded when a
// frame starts it and submitted right after that frame; the frame signals `fed` k once what the
// run reads is written, and the run waits for that and for run k-1, then signals `finished` k.
// A later frame that reads what run k wrote polls finished(k) and then waits for it on the GPU
// (wait_in), which costs nothing once it has been reached.
#pragma once

#include <cstdint>

#include <vulkan/vulkan.h>

#include "engine/graph/frame_slots.h"
#include "engine/graph/graph_runner.h"

namespace strata {
class Context;
}

namespace strata::graph {

// A timeline semaphore: a counter that submissions wait for and raise, and the host polls.
class Timeline {
 public:
  explicit Timeline(Context& ctx);
  ~Timeline();
  Timeline(const Timeline&) = delete;
  Timeline& operator=(const Timeline&) = delete;

  // The value reached so far (no wait).
  uint64_t value() const;
  // For a submission: wait for `value`, or signal it, at every stage.
  VkSemaphoreSubmitInfo at(uint64_t value) const;

 private:
  Context& ctx_;
  VkSemaphore semaphore_ = VK_NULL_HANDLE;
};

class SecondQueue {
 public:
  explicit SecondQueue(Context& ctx);

  // Records the next run of `graph` now, as it is bound (once the run before it has finished: at
  // most the Context's GPU timeout), and sets `frame`'s submission to feed it: the frame signals
  // `fed` and the run is submitted after it. Returns the run's number, counted from 1.
  uint64_t run_after(GraphRunner& frame, GraphRunner& graph);
  // Runs started so far.
  uint64_t started() const { return started_; }
  // Whether run `run` has finished (polls, no wait).
  bool finished(uint64_t run) const { return finished_.value() >= run; }
  // `frame`'s submission waits for run `run` to finish: the frame reads what the run wrote.
  void wait_in(GraphRunner& frame, uint64_t run) const;
  // Waits on the host until every run submitted has finished (like FrameSlots::next).
  void wait_idle() { slots_.wait_all(); }

 private:
  FrameSlots slots_;
  Timeline fed_;       // frame k wrote what run k reads
  Timeline finished_;  // run k finished
  uint64_t started_ = 0;
};

}  // namespace strata::graph
