#include "engine/graph/graph_runner.h"

#include <algorithm>
#include <string>

#include "engine/gpu/context.h"
#include "engine/gpu/vulkan_check.h"

namespace strata::graph {

const ResourceUse& PassContext::declared(ResourceId id) const {
  const PassInfo& pass = runner_->graph_.passes()[pass_];
  for (const ResourceUse& u : pass.uses) {
    if (u.resource == id) return u;
  }
  const auto& resources = runner_->graph_.resources();
  throw GraphError(
      "pass '" + pass.name + "' touches " +
      (id < resources.size() ? "'" + resources[id].name + "'" : "resource #" + std::to_string(id)) +
      ", which it did not declare");
}

VkBuffer PassContext::buffer(ResourceId id) const {
  declared(id);
  return runner_->bound_[id].buffer;
}
VkImage PassContext::image(ResourceId id) const {
  declared(id);
  return runner_->bound_[id].image;
}
uint64_t PassContext::allocation() const {
  return runner_->allocation();
}

VkImageView PassContext::view(ResourceId id) const {
  declared(id);
  return runner_->bound_[id].view;
}

void PassContext::copy_buffer(ResourceId from, ResourceId to, VkDeviceSize size) {
  const VkBufferCopy region{0, 0, size};
  vkCmdCopyBuffer(cmd, buffer(from), buffer(to), 1, &region);
}

void PassContext::begin_conditional(ResourceId predicate, VkDeviceSize offset) {
  const PassInfo& pass = runner_->graph_.passes()[pass_];
  declared(predicate);
  const bool conditional = std::any_of(pass.uses.begin(), pass.uses.end(), [&](const auto& u) {
    return u.resource == predicate && u.use == Use::conditional;
  });
  if (!conditional) {
    throw GraphError("pass '" + pass.name + "' reads a predicate from '" +
                     runner_->graph_.resources()[predicate].name +
                     "', which it did not declare conditional");
  }
  if (!runner_->begin_conditional_ || predicate_) {
    throw GraphError("pass '" + pass.name + "' begins a conditional block " +
                     (predicate_ ? "inside another" : "on a device without conditional rendering"));
  }
  VkConditionalRenderingBeginInfoEXT info{VK_STRUCTURE_TYPE_CONDITIONAL_RENDERING_BEGIN_INFO_EXT};
  info.buffer = runner_->bound_[predicate].buffer;
  info.offset = offset;
  runner_->begin_conditional_(cmd, &info);
  predicate_ = Predicate{predicate, offset};
}

void PassContext::end_conditional() {
  if (!predicate_) {
    throw GraphError("pass '" + runner_->graph_.passes()[pass_].name +
                     "' ends a conditional block it did not begin");
  }
  runner_->end_conditional_(cmd);
  predicate_.reset();
}

VkBuffer PassContext::indirect_buffer(ResourceId id) const {
  const PassInfo& pass = runner_->graph_.passes()[pass_];
  declared(id);
  for (const ResourceUse& u : pass.uses) {
    if (u.resource == id && u.use == Use::indirect) return runner_->bound_[id].buffer;
  }
  throw GraphError("pass '" + pass.name + "' dispatches from '" +
                   runner_->graph_.resources()[id].name + "', which it did not declare indirect");
}

void PassContext::prepare(const ComputePipeline& pipeline, const void* push, uint32_t size) {
  if (bound_ != &pipeline) bind(pipeline);
  if (push) pipeline.push_constants(cmd, push, size);
}

void PassContext::dispatch_threads(const ComputePipeline& pipeline, glm::uvec3 threads) {
  const std::array<uint32_t, 3> size = pipeline.local_size();
  vkCmdDispatch(cmd, group_count(threads.x, size[0]), group_count(threads.y, size[1]),
                group_count(threads.z, size[2]));
}

void PassContext::barrier() {
  record_barrier(false);
}

void PassContext::barrier_for_predicates() {
  record_barrier(true);
}

void PassContext::record_barrier(bool predicates) {
  const PassInfo& pass = runner_->graph_.passes()[pass_];
  if (pass.kind == PassKind::graphics) {
    throw GraphError("pass '" + pass.name +
                     "' asks for a barrier between its commands, but it is " + "a graphics pass");
  }
  SyncScope src, dst;
  if (pass.kind == PassKind::compute) {
    src = {VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT};
    dst = {VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
           VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT};
  } else {  // transfer: copies and fills that overwrite or read what the pass wrote before
    src = {VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT};
    dst = {VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
           VK_ACCESS_2_TRANSFER_READ_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT};
  }
  bool declared_predicates = false;
  for (const ResourceUse& u : pass.uses) {
    declared_predicates = declared_predicates || u.use == Use::conditional;
    if (u.use != Use::indirect) continue;
    dst.stage |= VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT;
    dst.access |= VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT;
  }
  if (predicates) {
    if (!declared_predicates) {
      throw GraphError("pass '" + pass.name +
                       "' asks for a barrier before predicates, but declared none conditional");
    }
    dst.stage |= VK_PIPELINE_STAGE_2_CONDITIONAL_RENDERING_BIT_EXT;
    dst.access |= VK_ACCESS_2_CONDITIONAL_RENDERING_READ_BIT_EXT;
  }
  record_memory_barrier(cmd, src, dst);
}

void PassContext::bind(const Pipeline& pipeline) {
  std::vector<DescriptorResource> resources;
  const PassInfo& pass = runner_->graph_.passes()[pass_];
  for (const ResourceUse& u : pass.uses) {
    if (!u.binding) continue;
    const GraphRunner::Bound& b = runner_->bound_.at(u.resource);
    const VkSampler sampler = u.use == Use::sampled ? runner_->linear_sampler_ : VK_NULL_HANDLE;
    resources.push_back({*u.binding, u.array_element, b.buffer, b.view,
                         runner_->compiled_.layout[pass_][u.resource], sampler});
  }
  pipeline.bind(cmd, resources);
  bound_ = &pipeline;
}

GraphRunner::GraphRunner(Context& ctx, Graph graph)
    : ctx_(ctx), graph_(std::move(graph)), compiled_(compile(graph_)) {
  bound_.resize(graph_.resources().size());
  owned_.resize(graph_.resources().size());
  for (size_t i = 0; i < graph_.resources().size(); ++i) {
    const ResourceInfo& r = graph_.resources()[i];
    if (!r.imported) continue;
    bound_[i] = r.is_image ? Bound{VK_NULL_HANDLE, r.imported_image.image, r.imported_image.view,
                                   r.imported_image.format}
                           : Bound{r.imported_buffer.buffer};
  }
  set_frames_in_flight(1);
  VkSamplerCreateInfo sampler{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  sampler.magFilter = sampler.minFilter = VK_FILTER_LINEAR;
  sampler.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
  sampler.addressModeU = sampler.addressModeV = sampler.addressModeW =
      VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  STRATA_VK(vkCreateSampler(ctx_.device(), &sampler, nullptr, &linear_sampler_));
  if (ctx_.conditional_rendering()) {
    begin_conditional_ = reinterpret_cast<PFN_vkCmdBeginConditionalRenderingEXT>(
        vkGetDeviceProcAddr(ctx_.device(), "vkCmdBeginConditionalRenderingEXT"));
    end_conditional_ = reinterpret_cast<PFN_vkCmdEndConditionalRenderingEXT>(
        vkGetDeviceProcAddr(ctx_.device(), "vkCmdEndConditionalRenderingEXT"));
  }
}

GraphRunner::~GraphRunner() {
  // (frames may still run, one in flight too where a window shows it; never throws, and leaves
  // what a hung GPU may still use)
  if (!ctx_.drain() && !ctx_.may_destroy()) return;
  vkDestroySampler(ctx_.device(), linear_sampler_, nullptr);
  for (VkQueryPool pool : queries_) vkDestroyQueryPool(ctx_.device(), pool, nullptr);
}

void GraphRunner::set_frames_in_flight(uint32_t frames) {
  if (frames == 0) throw Error("render graph: no frames in flight");
  if (!queries_.empty()) ctx_.wait_idle("the frames in flight (their query pools are replaced)");
  for (VkQueryPool pool : queries_) vkDestroyQueryPool(ctx_.device(), pool, nullptr);
  queries_.assign(frames, VK_NULL_HANDLE);
  slot_stamps_.assign(frames, stamps_);
  VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  info.queryType = VK_QUERY_TYPE_TIMESTAMP;
  info.queryCount = static_cast<uint32_t>(2 * std::max<size_t>(1, graph_.passes().size()));
  for (VkQueryPool& pool : queries_) {
    STRATA_VK(vkCreateQueryPool(ctx_.device(), &info, nullptr, &pool));
  }
  slot_ = 0;
}

void GraphRunner::set_viewport(Extent viewport) {
  if (viewport == viewport_) return;
  if (viewport.width == 0 || viewport.height == 0) throw Error("render graph: empty viewport");
  // (resources of frames still in flight are replaced: those frames finish first)
  if (viewport_.width != 0 && frames_in_flight() > 1) {
    ctx_.wait_idle("the frames in flight (the graph's resources are replaced)");
  }
  viewport_ = viewport;
  ++allocation_;
  for (size_t i = 0; i < graph_.resources().size(); ++i) {
    const ResourceInfo& r = graph_.resources()[i];
    if (r.imported) continue;
    try {
      if (r.is_image) {
        const Extent e = r.image.fixed.width ? r.image.fixed : viewport;
        ImageDesc desc{r.image.format,     {e.width, e.height, 1}, VK_IMAGE_TYPE_2D,
                       compiled_.usage[i], r.image.layers,         r.image.array};
        Image& image = owned_[i].emplace<Image>(ctx_, desc);
        bound_[i] = {VK_NULL_HANDLE, image.handle(), image.view(), r.image.format};
        if (r.image.keep) put_in_layout(image, compiled_.kept_layout[i]);
      } else {
        const VkDeviceSize size = std::max<VkDeviceSize>(4, r.buffer.size(viewport));
        Buffer& buffer =
            owned_[i].emplace<Buffer>(ctx_, size, compiled_.usage[i], MemoryKind::device_local);
        bound_[i] = {buffer.handle()};
      }
    } catch (const DeviceLost&) {
      throw;
    } catch (const Error& e) {
      // Which resource could not be had, at which size (the HA-Buffer is render.keys and
      // render.payload): the graph is left without it, so it cannot run until a set_viewport()
      // that succeeds.
      viewport_ = {};
      throw Error("render graph: '" + r.name + "' for a " + std::to_string(viewport.width) + "x" +
                  std::to_string(viewport.height) + " viewport: " + e.what());
    }
  }
}

// A new kept image, empty, in the layout every run expects it in.
void GraphRunner::put_in_layout(const Image& image, VkImageLayout layout) {
  ctx_.run_now([&](VkCommandBuffer cmd) {
    const VkImageMemoryBarrier2 b =
        image_barrier(image.handle(), whole_image(image.desc().format, VK_REMAINING_ARRAY_LAYERS),
                      VK_IMAGE_LAYOUT_UNDEFINED, layout, {},
                      {VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                       VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT});
    record_barriers(cmd, {&b, 1});
  });
}

void GraphRunner::reallocate() {
  const Extent viewport = viewport_;
  // (resources of frames still in flight are replaced: those frames finish first)
  if (frames_in_flight() > 1) {
    ctx_.wait_idle("the frames in flight (the graph's resources are replaced)");
  }
  viewport_ = {};
  set_viewport(viewport);
}

std::vector<std::byte> GraphRunner::download_image(ResourceId id) {
  const Image* image = std::get_if<Image>(&owned_.at(id));
  if (!image)
    throw Error("render graph: '" + graph_.resources()[id].name + "' is not a transient image");
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
  for (const auto& pass_layouts : compiled_.layout) {
    if (pass_layouts[id] != VK_IMAGE_LAYOUT_UNDEFINED) layout = pass_layouts[id];
  }
  return download(ctx_, *image, layout);
}

std::vector<std::byte> GraphRunner::download_buffer(ResourceId id) {
  const Buffer* buffer = std::get_if<Buffer>(&owned_.at(id));
  if (!buffer)
    throw Error("render graph: '" + graph_.resources()[id].name + "' is not a transient buffer");
  return download(ctx_, *buffer);
}

void GraphRunner::bind_buffer(ResourceId id, VkBuffer buffer) {
  bound_.at(id) = {buffer};
}

void GraphRunner::bind_image(ResourceId id, VkImage image, VkImageView view, VkFormat format) {
  bound_.at(id) = {VK_NULL_HANDLE, image, view, format};
}

void GraphRunner::emit(VkCommandBuffer cmd, std::span<const Barrier> barriers) const {
  if (barriers.empty()) return;
  std::vector<VkBufferMemoryBarrier2> buffers;
  std::vector<VkImageMemoryBarrier2> images;
  for (const Barrier& b : barriers) {
    const Bound& r = bound_[b.resource];
    const SyncScope src{b.src_stage, b.src_access}, dst{b.dst_stage, b.dst_access};
    if (b.is_image) {
      images.push_back(image_barrier(r.image, whole_image(r.format, VK_REMAINING_ARRAY_LAYERS),
                                     b.old_layout, b.new_layout, src, dst));
    } else {
      buffers.push_back(buffer_barrier(r.buffer, src, dst));
    }
  }
  record_barriers(cmd, images, buffers);
}

void GraphRunner::check_bound() const {
  if (viewport_.width == 0) throw Error("render graph: set_viewport() before record()");
  for (size_t i = 0; i < bound_.size(); ++i) {
    if (!bound_[i].buffer && !bound_[i].image) {
      throw Error("render graph: imported resource '" + graph_.resources()[i].name +
                  "' is not bound");
    }
  }
}

bool GraphRunner::stamps_begin(uint32_t p, Stamps stamps) const {
  const auto& passes = graph_.passes();
  if (stamps == Stamps::frame) return p == 0;
  return stamps == Stamps::pass || p == 0 || passes[p - 1].group != passes[p].group;
}

bool GraphRunner::stamps_end(uint32_t p, Stamps stamps) const {
  const auto& passes = graph_.passes();
  if (stamps == Stamps::frame) return p + 1 == passes.size();
  return stamps == Stamps::pass || p + 1 == passes.size() || passes[p + 1].group != passes[p].group;
}

void GraphRunner::record_pass(VkCommandBuffer cmd, uint32_t p) {
  emit(cmd, compiled_.pass_barriers[p]);
  if (stamps_begin(p, slot_stamps_[slot_])) {
    vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, queries_[slot_], 2 * p);
  }
  PassContext pc;
  pc.cmd = cmd;
  pc.viewport = viewport_;
  pc.runner_ = this;
  pc.pass_ = p;
  try {
    graph_.passes()[p].record(pc);
  } catch (...) {
    if (pc.predicate_) pc.end_conditional();  // (so that the command buffer ends cleanly)
    throw;
  }
  if (pc.predicate_) {
    pc.end_conditional();  // (the command buffer still ends cleanly)
    throw GraphError("pass '" + graph_.passes()[p].name + "' leaves a conditional block open");
  }
  if (stamps_end(p, slot_stamps_[slot_])) {
    vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, queries_[slot_], 2 * p + 1);
  }
}

void GraphRunner::record(VkCommandBuffer cmd, uint32_t slot) {
  record_passes(cmd, 0, static_cast<PassId>(graph_.passes().size()), slot);
}

void GraphRunner::record_passes(VkCommandBuffer cmd, PassId first, PassId end, uint32_t slot) {
  check_bound();
  if (slot >= queries_.size()) {
    throw Error("render graph: frame slot " + std::to_string(slot) + " of " +
                std::to_string(queries_.size()) + " frames in flight");
  }
  const auto passes = static_cast<PassId>(graph_.passes().size());
  if (first > end || end > passes) {
    throw Error("render graph: passes " + std::to_string(first) + " to " + std::to_string(end) +
                " of " + std::to_string(passes));
  }
  slot_ = slot;
  if (first == 0) slot_stamps_[slot_] = stamps_;
  if (first == 0 && frames_in_flight() > 1) {
    // Frames share the transient resources and follow each other on the queue: everything the
    // earlier frames did is done and visible before this one starts (compile() orders the passes
    // inside one frame only).
    record_memory_barrier(cmd, {VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT},
                          {VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                           VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT});
  }
  if (first == 0) {
    slot_uploads_.resize(queries_.size());
    slot_uploads_[slot_] = take_uploads();  // (the slot's last frame has run)
    slot_uploads_[slot_].record(cmd);
  }
  if (first < end) vkCmdResetQueryPool(cmd, queries_[slot_], 2 * first, 2 * (end - first));
  for (PassId p = first; p < end; ++p) record_pass(cmd, p);
  if (end == passes) emit(cmd, compiled_.final_barriers);
}

void GraphRunner::run_now() {
  run_passes(0, static_cast<PassId>(graph_.passes().size()));
}

void GraphRunner::run_passes(PassId first, PassId end) {
  ctx_.run_now([&](VkCommandBuffer cmd) { record_passes(cmd, first, end); });
}

std::vector<PassTiming> GraphRunner::timings(uint32_t slot) const {
  const VkQueryPool pool = queries_.at(slot);
  const auto& passes = graph_.passes();
  std::vector<uint64_t> stamps(2 * passes.size());
  // (stamps that were not written must not be waited for: read those that were, one by one)
  const auto read = [&](uint32_t query) {
    STRATA_VK(vkGetQueryPoolResults(ctx_.device(), pool, query, 1, sizeof(uint64_t), &stamps[query],
                                    sizeof(uint64_t),
                                    VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
  };
  const Stamps mode = slot_stamps_.at(slot);
  if (mode == Stamps::pass && !passes.empty()) {
    STRATA_VK(vkGetQueryPoolResults(ctx_.device(), pool, 0, static_cast<uint32_t>(stamps.size()),
                                    stamps.size() * sizeof(uint64_t), stamps.data(),
                                    sizeof(uint64_t),
                                    VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
  } else {
    for (uint32_t p = 0; p < passes.size(); ++p) {
      if (stamps_begin(p, mode)) read(2 * p);
      if (stamps_end(p, mode)) read(2 * p + 1);
    }
  }
  std::vector<PassTiming> out;
  const double to_ms = ctx_.timestamp_period_ns() * 1e-6;
  const auto since_start = [&](uint32_t query) {
    return static_cast<double>(stamps[query] - stamps[0]) * to_ms;
  };
  uint32_t group_first = 0;
  for (uint32_t p = 0; p < passes.size(); ++p) {
    if (mode == Stamps::pass) {
      const double begin = since_start(2 * p), end = since_start(2 * p + 1);
      out.push_back({passes[p].name, passes[p].group, end - begin, begin, end});
      continue;
    }
    if (stamps_begin(p, mode)) group_first = p;
    if (stamps_end(p, mode)) {
      const double begin = since_start(2 * group_first), end = since_start(2 * p + 1);
      const std::string name = mode == Stamps::frame ? "frame" : passes[p].group;
      out.push_back({name, name, end - begin, begin, end});
    }
  }
  return out;
}

}  // namespace strata::graph
