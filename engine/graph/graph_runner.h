// Runs a compiled render graph on a device: creates its transient resources for a viewport,
// records every pass behind the barriers compile() derived, and wraps each pass in timestamps.
#pragma once

#include <functional>
#include <memory>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "engine/graph/render_graph.h"
#include "engine/gpu/resources.h"
#include "engine/gpu/shader_library.h"

namespace strata {
class Context;
}

namespace strata::graph {

class GraphRunner;

// What a pass's record function sees: its command buffer, the viewport, and its resources.
class PassContext {
 public:
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  Extent viewport;

  VkBuffer buffer(ResourceId id) const;
  VkImage image(ResourceId id) const;
  VkImageView view(ResourceId id) const;
  // Binds `pipeline` and pushes every resource this pass declared with a binding index (sampled
  // images with the graph's linear clamp-to-edge sampler).
  void bind(const Pipeline& pipeline) const;

 private:
  friend class GraphRunner;
  const GraphRunner* runner_ = nullptr;
  uint32_t pass_ = 0;
};

struct PassTiming {
  std::string name;
  std::string group;
  double ms = 0.0;
  double begin_ms = 0.0;  // from the start of the run, so a group's span can be taken
  double end_ms = 0.0;
};

class GraphRunner {
 public:
  GraphRunner(Context& ctx, Graph graph);
  ~GraphRunner();

  // Creates (or re-creates, when it changed) every transient resource for `viewport`.
  void set_viewport(Extent viewport);
  Extent viewport() const { return viewport_; }

  // Imported resources are bound before each record.
  void bind_buffer(ResourceId id, VkBuffer buffer);
  void bind_image(ResourceId id, VkImage image, VkImageView view, VkFormat format);

  void record(VkCommandBuffer cmd);
  // Records into a fresh command buffer, submits and waits (headless runs, benchmarks, tests).
  void run_now();
  // The same work split into one submission per run of passes, waiting on the host after every
  // pass for which `split_after` is true and calling `after` there: the structure of a program
  // that returns to the CPU between passes (benchmark baselines).
  void run_split(const std::function<bool(uint32_t pass)>& split_after,
                 const std::function<void(uint32_t pass)>& after);

  // Re-creates the transient resources (after a size function's answer changed, e.g. a grown
  // hash table), keeping the viewport.
  void reallocate();
  // The texels of a transient image after the last completed run (waits; for tools and tests).
  std::vector<std::byte> download_image(ResourceId id);
  // The bytes of a transient buffer after the last completed run (waits; tools and tests).
  std::vector<std::byte> download_buffer(ResourceId id);

  // Timestamps around every pass (the default), or only where a group of passes begins and
  // ends: a group's time without the cost of stamping each of its passes (benchmarks).
  void set_timestamps_per_pass(bool per_pass) { per_pass_stamps_ = per_pass; }
  // GPU time of each pass of the last completed run; with group stamps only, one entry per
  // group (named after it) instead.
  std::vector<PassTiming> timings() const;

  const Graph& graph() const { return graph_; }
  // Mutable so that a test can drop a barrier and show that validation catches it.
  CompiledGraph& compiled() { return compiled_; }

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
  // Whether pass p stamps its begin / its end (every pass, or a group's first / last).
  bool stamps_begin(uint32_t pass) const;
  bool stamps_end(uint32_t pass) const;

  Context& ctx_;
  bool per_pass_stamps_ = true;
  Graph graph_;
  CompiledGraph compiled_;
  Extent viewport_{};
  std::vector<std::variant<std::monostate, Buffer, Image>> owned_;
  std::vector<Bound> bound_;
  VkQueryPool queries_ = VK_NULL_HANDLE;
  VkSampler linear_sampler_ = VK_NULL_HANDLE;
};

}  // namespace strata::graph
