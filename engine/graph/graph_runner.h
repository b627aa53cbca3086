// Runs a compiled render graph on a device: creates its transient resources for a viewport,
// records every pass behind the barriers compile() derived, and wraps each pass in timestamps.
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <glm/glm.hpp>

#include "engine/gpu/resources.h"
#include "engine/gpu/shader_library.h"
#include "engine/graph/render_graph.h"

namespace strata {
class Context;
}

namespace strata::graph {

class GraphRunner;

// What a pass's record function sees: its command buffer, the viewport, and the resources it
// declared. Asking for one it did not declare is a GraphError naming the pass and the resource.
class PassContext {
 public:
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  Extent viewport;

  VkBuffer buffer(ResourceId id) const;
  VkImage image(ResourceId id) const;
  VkImageView view(ResourceId id) const;
  // GraphRunner::allocation() of the runner recording the pass.
  uint64_t allocation() const;
  // Binds `pipeline` and pushes every resource this pass declared with a binding index (sampled
  // images with the graph's linear clamp-to-edge sampler).
  void bind(const Pipeline& pipeline);
  // Copies the first `size` bytes of buffer `from` to the start of buffer `to` (a transfer pass
  // declares them transfer_src and transfer_dst).
  void copy_buffer(ResourceId from, ResourceId to, VkDeviceSize size);

  // Binds `pipeline` (unless this pass bound it last), pushes `push` and dispatches: enough
  // workgroups of the pipeline's reflected size to cover `threads`, exactly `groups`, or the
  // counts in the indirect-declared buffer `args` at `offset`.
  template <typename Push>
  void dispatch(const ComputePipeline& pipeline, const Push& push, glm::uvec3 threads) {
    prepare(pipeline, &push, sizeof push);
    dispatch_threads(pipeline, threads);
  }
  void dispatch(const ComputePipeline& pipeline, glm::uvec3 threads) {
    prepare(pipeline, nullptr, 0);
    dispatch_threads(pipeline, threads);
  }
  template <typename Push>
  void dispatch_groups(const ComputePipeline& pipeline, const Push& push, glm::uvec3 groups) {
    prepare(pipeline, &push, sizeof push);
    vkCmdDispatch(cmd, groups.x, groups.y, groups.z);
  }
  template <typename Push>
  void dispatch_indirect(const ComputePipeline& pipeline, const Push& push, ResourceId args,
                         VkDeviceSize offset) {
    const VkBuffer buffer = indirect_buffer(args);
    prepare(pipeline, &push, sizeof push);
    vkCmdDispatchIndirect(cmd, buffer, offset);
  }

  // Between two dependent commands of this pass: in a compute pass, its shader writes become
  // visible to its later dispatches (and to their indirect reads when it declared an indirect
  // use); in a transfer pass, its copies and fills are ordered. The graph's barriers order
  // passes; this orders the steps inside one.
  void barrier();
  // barrier(), after which the conditional-rendering predicates read (begin_conditional) see
  // what the pass wrote before it too. (Kept apart: on a GPU a barrier that waits for the
  // command processor's reads costs more than one between shaders; docs/performance.md.)
  void barrier_for_predicates();

  // The dispatches recorded up to end_conditional() run only where the uint32 at `offset` of
  // `predicate` (declared conditional) is not 0 (VK_EXT_conditional_rendering:
  // Context::conditional_rendering()). Barriers in between are not conditional. (Each block has a
  // cost of its own: a block around each of the tidy-up's idle dispatches cost more than the
  // dispatches did; docs/performance.md.)
  void begin_conditional(ResourceId predicate, VkDeviceSize offset);
  void end_conditional();

 private:
  friend class GraphRunner;
  const ResourceUse& declared(ResourceId id) const;
  VkBuffer indirect_buffer(ResourceId id) const;
  void record_barrier(bool predicates);
  void prepare(const ComputePipeline& pipeline, const void* push, uint32_t size);
  void dispatch_threads(const ComputePipeline& pipeline, glm::uvec3 threads);

  GraphRunner* runner_ = nullptr;
  PassId pass_ = 0;
  const Pipeline* bound_ = nullptr;  // the pipeline this pass bound last in `cmd`
  struct Predicate {
    ResourceId resource;
    VkDeviceSize offset;
  };
  std::optional<Predicate> predicate_;  // between begin_conditional and end_conditional
};

struct PassTiming {
  std::string name;
  std::string group;
  double ms = 0.0;
  double begin_ms = 0.0;  // from the start of the run, so a group's span can be taken
  double end_ms = 0.0;
};

// What the submission of a frame adds to the semaphores its output waits for and signals, and
// what follows it (a placement beside the frames waits for the frame that feeds it and is
// submitted after it): set while the frame is prepared, read by whoever submits it.
struct FrameSubmission {
  std::vector<VkSemaphoreSubmitInfo> wait, signal;
  std::function<void()> submitted;  // called once the frame is submitted
};

class GraphRunner {
 public:
  GraphRunner(Context& ctx, Graph graph);
  ~GraphRunner();

  // Creates (or re-creates, when it changed) every transient resource for `viewport`.
  void set_viewport(Extent viewport);
  Extent viewport() const { return viewport_; }
  // Counts the times the transient resources were made (a kept image made anew has no content).
  uint64_t allocation() const { return allocation_; }

  // Re-binds an import whose handle changes between runs (a swapchain image, a resized
  // readback); the others keep the handle they were imported with.
  void bind_buffer(ResourceId id, VkBuffer buffer);
  void bind_image(ResourceId id, VkImage image, VkImageView view, VkFormat format);

  // Copies recorded at the start of the next frame (record, record_passes from pass 0, run_now)
  // before its first pass, visible to all of them: new contents for imported buffers and images
  // (a label edit's glyphs and atlases) without a wait on the host. Their staging memory is kept
  // until that frame slot is recorded again, or the runner goes.
  void upload_in_next_frame(Uploads&& uploads) { pending_uploads_.append(std::move(uploads)); }
  // The uploads no frame has recorded yet, for the runner that replaces this one.
  Uploads take_uploads() { return std::exchange(pending_uploads_, {}); }

  // Frames recorded before the earlier ones finished (the viewer keeps two in flight): each
  // frame slot has its own timestamps, and a frame first waits on the queue for everything the
  // frames before it did. Waits for the device when it changes.
  void set_frames_in_flight(uint32_t frames);
  uint32_t frames_in_flight() const { return static_cast<uint32_t>(queries_.size()); }

  // Records one frame into `cmd`, its timestamps into frame slot `slot`.
  void record(VkCommandBuffer cmd, uint32_t slot = 0);
  // Records passes [first, end) into `cmd` with their barriers and timestamps: a frame recorded
  // range after range, in order, does what record() does (work that returns to the host between
  // passes); timings() is the frame's once every range of it has run.
  void record_passes(VkCommandBuffer cmd, PassId first, PassId end, uint32_t slot = 0);
  // Records into a fresh command buffer, submits and waits (headless runs, benchmarks, tests):
  // the whole frame, or passes [first, end) of it.
  void run_now();
  void run_passes(PassId first, PassId end);

  // Re-creates the transient resources (after a size function's answer changed, e.g. a grown
  // hash table), keeping the viewport.
  void reallocate();
  // The texels of a transient image after the last completed run (waits; for tools and tests).
  std::vector<std::byte> download_image(ResourceId id);
  // The bytes of a transient buffer after the last completed run (waits; tools and tests).
  std::vector<std::byte> download_buffer(ResourceId id);

  // Timestamps around every pass (the default), or only where a group of passes begins and
  // ends: a group's time without the cost of stamping each of its passes (benchmarks).
  // Each frame slot is read as its last frame was stamped, so the stamping may change while
  // frames are in flight.
  void set_timestamps_per_pass(bool per_pass) { stamps_ = per_pass ? Stamps::pass : Stamps::group; }
  // Only where the frame begins and ends: one entry, "frame" (the least disturbed whole time).
  void set_timestamps_per_frame() { stamps_ = Stamps::frame; }
  // GPU time of each pass of the last completed run; with group stamps only, one entry per
  // group (named after it) instead. With frames in flight: of the last completed frame of `slot`.
  std::vector<PassTiming> timings(uint32_t slot = 0) const;

  const Graph& graph() const { return graph_; }
  FrameSubmission& submission() { return submission_; }
  // Mutable so that a test can drop a barrier and show that validation catches it.
  CompiledGraph& compiled() { return compiled_; }
  const CompiledGraph& compiled() const { return compiled_; }

 private:
  friend class PassContext;
  struct Bound {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkImage image = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
    VkFormat format = VK_FORMAT_UNDEFINED;
  };
  void emit(VkCommandBuffer cmd, std::span<const Barrier> barriers) const;
  void check_bound() const;
  void record_pass(VkCommandBuffer cmd, uint32_t pass);
  void put_in_layout(const Image& image, VkImageLayout layout);
  enum class Stamps { pass, group, frame };
  // Whether pass p stamps its begin / its end (every pass, a group's first / last, or the
  // frame's).
  bool stamps_begin(uint32_t pass, Stamps stamps) const;
  bool stamps_end(uint32_t pass, Stamps stamps) const;

  Context& ctx_;
  Stamps stamps_ = Stamps::pass;
  std::vector<Stamps> slot_stamps_;  // how each slot's last frame was stamped
  Graph graph_;
  CompiledGraph compiled_;
  Extent viewport_{};
  std::vector<std::variant<std::monostate, Buffer, Image>> owned_;
  std::vector<Bound> bound_;
  std::vector<VkQueryPool> queries_;  // one per frame slot
  uint32_t slot_ = 0;                 // the slot being recorded
  uint64_t allocation_ = 0;
  FrameSubmission submission_;
  Uploads pending_uploads_;
  std::vector<Uploads> slot_uploads_;  // per frame slot, what its last frame copied
  VkSampler linear_sampler_ = VK_NULL_HANDLE;
  PFN_vkCmdBeginConditionalRenderingEXT begin_conditional_ = nullptr;  // with the extension only
  PFN_vkCmdEndConditionalRenderingEXT end_conditional_ = nullptr;
};

}  // namespace strata::graph
