#include "frame/placement_beside.h"

#include <algorithm>

#include "engine/core/error.h"
#include "engine/gpu/context.h"
#include "engine/gpu/resources.h"
#include "engine/gpu/shader_library.h"
#include "shared/placement_snapshot.h"

namespace strata {

using graph::Use;

namespace {

constexpr VkBufferUsageFlags kCopied = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                       VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                       VK_BUFFER_USAGE_TRANSFER_DST_BIT;

// (used by both queues' families)
Buffer zeroed_buffer(Context& ctx, VkDeviceSize size) {
  Buffer buffer(ctx, size, kCopied, MemoryKind::device_local, true);
  upload(ctx, buffer, std::vector<std::byte>(size));
  return buffer;
}

}  // namespace

void add_snapshot_pass(graph::Graph& graph, const ComputePipeline& pipeline,
                       const SnapshotImages& images, std::function<uint32_t()> layers_now) {
  graph.add_pass(
      {"placement.snapshot",
       graph::PassKind::compute,
       {{images.final_image, Use::storage_read, SNAPSHOT_BINDING_FINAL},
        {images.layers, Use::storage_read, SNAPSHOT_BINDING_LAYERS},
        {images.final_copy, Use::storage_write, SNAPSHOT_BINDING_FINAL_COPY},
        {images.layers_copy, Use::storage_write, SNAPSHOT_BINDING_LAYERS_COPY}},
       [&pipeline, layers_now = std::move(layers_now)](graph::PassContext& pc) {
         const uint32_t layers = layers_now();
         if (layers == 0) return;
         const gpu::SnapshotParams params{{pc.viewport.width, pc.viewport.height}, layers, 0u};
         pc.dispatch(pipeline, params, {pc.viewport.width, pc.viewport.height, 1});
       },
       "placement"});
}

PlacementBeside::PlacementBeside(Context& ctx, Placement& placement, LabelForces& forces,
                                 uint32_t label_count)
    : ctx_(ctx),
      placement_(placement),
      forces_(forces),
      label_count_(std::max(label_count, 1u)),
      snapshot_(ctx, "placement_snapshot.comp"),
      published_targets_(zeroed_buffer(ctx, label_count_ * sizeof(gpu::PlacementGpu))),
      published_labels_(zeroed_buffer(ctx, label_count_ * sizeof(gpu::LabelGpu))),
      published_order_(zeroed_buffer(ctx, label_count_ * sizeof(uint32_t))),
      adopted_targets_(zeroed_buffer(ctx, label_count_ * sizeof(gpu::PlacementGpu))),
      adopted_labels_(zeroed_buffer(ctx, label_count_ * sizeof(gpu::LabelGpu))),
      adopted_order_(zeroed_buffer(ctx, label_count_ * sizeof(uint32_t))),
      runs_(ctx) {}

void PlacementBeside::wait_idle() {
  runs_.wait_idle();
}

bool PlacementBeside::take_trial(const std::function<void()>& read) {
  if (!trial_finished()) return false;
  taken_ = runs_.started();
  placement_.readback().use_slot(*runner_, started_slot_);
  read();
  placement_.readback().use_slot(*runner_, adopted_slot_);
  return true;
}

void PlacementBeside::build(uint32_t layer_count, graph::Extent size) {
  wait_idle();
  if (trial_) taken_ = runs_.started();  // (a trial for the old graph: its results are not read)
  layer_count_ = layer_count;
  placement_.readback().set_slots(2);
  adopted_slot_ = 0;
  for (Snapshot& s : snapshots_) {
    const VkImageUsageFlags usage = VK_IMAGE_USAGE_STORAGE_BIT;
    s.final = Image(ctx_, {.format = VK_FORMAT_R8G8B8A8_UNORM,
                           .extent = {size.width, size.height, 1},
                           .usage = usage,
                           .both_queues = true});
    s.layers = Image(ctx_, {.format = VK_FORMAT_R16G16B16A16_SFLOAT,
                            .extent = {size.width, size.height, 1},
                            .usage = usage,
                            .layers = layer_count,
                            .array = true,
                            .both_queues = true});
    s.state = Buffer(ctx_, label_count_ * sizeof(gpu::LabelStateGpu), kCopied,
                     MemoryKind::device_local, true);
  }
  graph::Graph graph;
  const auto snapshot_image = [&graph](const char* name, VkFormat format) {
    // (as the frame that started the placement left it; its submission's signal is waited for
    // at every stage)
    return graph.import_image(name, {.format = format,
                                     .has_content = true,
                                     .initial_layout = VK_IMAGE_LAYOUT_GENERAL,
                                     .initial_stage = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT});
  };
  const graph::ResourceId final_image = snapshot_image("beside.final", VK_FORMAT_R8G8B8A8_UNORM);
  const graph::ResourceId layers = snapshot_image("beside.layers", VK_FORMAT_R16G16B16A16_SFLOAT);
  const graph::ResourceId state = graph.import_buffer("beside.state", {.has_content = true});
  runner_snapshot_ids_ = {final_image, layers, state};
  const Placement::Outputs placed = placement_.add_to(
      graph, {.final_image = final_image,
              .layers = layers,
              .layer_count = layer_count,
              .adjust_labels = [this, state](graph::Graph& g, graph::ResourceId labels) {
                forces_.add_previous(g, labels, state);
              }});
  const auto published = [&graph](const char* name, const Buffer& buffer) {
    return graph.import_buffer(name, {.buffer = buffer.handle()});
  };
  const graph::ResourceId targets = published("beside.published_targets", published_targets_);
  const graph::ResourceId labels = published("beside.published_labels", published_labels_);
  const graph::ResourceId order = published("beside.published_order", published_order_);
  const VkDeviceSize n = label_count_;
  graph.add_pass({"placement.publish",
                  graph::PassKind::transfer,
                  {{placed.placements, Use::transfer_src},
                   {placed.labels, Use::transfer_src},
                   {placed.order, Use::transfer_src},
                   {targets, Use::transfer_dst},
                   {labels, Use::transfer_dst},
                   {order, Use::transfer_dst}},
                  [=](graph::PassContext& pc) {
                    pc.copy_buffer(placed.placements, targets, n * sizeof(gpu::PlacementGpu));
                    pc.copy_buffer(placed.labels, labels, n * sizeof(gpu::LabelGpu));
                    pc.copy_buffer(placed.order, order, n * sizeof(uint32_t));
                  },
                  "placement"});
  runner_ = std::make_unique<graph::GraphRunner>(ctx_, std::move(graph));
  runner_->set_viewport(size);
}

PlacementBeside::FrameIds PlacementBeside::add_to_frame(graph::Graph& graph,
                                                        const VolumeRenderer::Outputs& rendered,
                                                        graph::ResourceId state) {
  // The snapshot the next placement reads (bound in prepare): written only by the frame that
  // starts it, left as the copy leaves it.
  const auto snapshot_image = [&graph](const char* name, VkFormat format) {
    return graph.import_image(name, {.format = format});
  };
  const graph::ResourceId final_image = snapshot_image("beside.final", VK_FORMAT_R8G8B8A8_UNORM);
  const graph::ResourceId layers = snapshot_image("beside.layers", VK_FORMAT_R16G16B16A16_SFLOAT);
  frame_snapshot_ids_[0] = final_image;
  frame_snapshot_ids_[1] = layers;
  const VkDeviceSize n = label_count_;
  add_snapshot_pass(graph, snapshot_, {rendered.final, rendered.layers, final_image, layers},
                    [this] { return start_now_ ? layer_count_ : 0u; });
  const auto imported = [&graph](const char* name, const Buffer& buffer) {
    return graph.import_buffer(name, {.buffer = buffer.handle(), .has_content = true});
  };
  const graph::ResourceId published_targets =
      imported("beside.published_targets", published_targets_);
  const graph::ResourceId published_labels = imported("beside.published_labels", published_labels_);
  const graph::ResourceId published_order = imported("beside.published_order", published_order_);
  const graph::ResourceId targets = imported("beside.adopted_targets", adopted_targets_);
  const graph::ResourceId placed = imported("beside.adopted_labels", adopted_labels_);
  const graph::ResourceId order = imported("beside.adopted_order", adopted_order_);
  graph.add_pass({"placement.adopt",
                  graph::PassKind::transfer,
                  {{published_targets, Use::transfer_src},
                   {published_labels, Use::transfer_src},
                   {published_order, Use::transfer_src},
                   {targets, Use::transfer_dst},
                   {placed, Use::transfer_dst},
                   {order, Use::transfer_dst}},
                  [=, this](graph::PassContext& pc) {
                    if (!adopt_now_) return;
                    pc.copy_buffer(published_targets, targets, n * sizeof(gpu::PlacementGpu));
                    pc.copy_buffer(published_labels, placed, n * sizeof(gpu::LabelGpu));
                    pc.copy_buffer(published_order, order, n * sizeof(uint32_t));
                  },
                  "placement"});
  const graph::ResourceId labels =
      graph.add_buffer("frame.labels", {[n](graph::Extent) { return n * sizeof(gpu::LabelGpu); }});
  graph.add_pass({"labels.upload",
                  graph::PassKind::transfer,
                  {{labels, Use::transfer_dst}},
                  [this, labels](graph::PassContext& pc) {
                    record_update(pc.cmd, pc.buffer(labels), 0, as_bytes(frame_labels_));
                  },
                  "labels"});
  forces_.add_previous(graph, labels, state);
  return {labels, forces_.add_follow(graph, labels, placed, targets), order};
}

void PlacementBeside::add_state_snapshot(graph::Graph& graph, graph::ResourceId state) {
  const graph::ResourceId saved = graph.import_buffer("beside.state", {});
  frame_snapshot_ids_[2] = saved;
  const VkDeviceSize bytes = label_count_ * sizeof(gpu::LabelStateGpu);
  graph.add_pass({"placement.snapshot_state",
                  graph::PassKind::transfer,
                  {{state, Use::transfer_src}, {saved, Use::transfer_dst}},
                  [=, this](graph::PassContext& pc) {
                    if (start_now_) pc.copy_buffer(state, saved, bytes);
                  },
                  "labels"});
}

bool PlacementBeside::finished() const {
  return runs_.finished(runs_.started());
}

void PlacementBeside::prepare(graph::GraphRunner& frame, const std::vector<gpu::LabelGpu>& labels,
                              bool trial) {
  if (!runner_) throw Error("placement beside the frames: build() before prepare()");
  frame_labels_ = labels;
  frame.submission() = {};
  adopt_now_ = start_now_ = false;
  if (trial_finished()) taken_ = runs_.started();  // (a trial nobody read: dropped)
  if (runs_.started() > taken_ && !trial_ && finished()) {
    adopt();
    runs_.wait_in(frame, taken_);
  }
  // (the frames write the snapshot of the placement after the one in flight)
  const Snapshot& next = snapshots_[(runs_.started() + 1) % 2];
  frame.bind_image(frame_snapshot_ids_[0], next.final.handle(), next.final.view(),
                   VK_FORMAT_R8G8B8A8_UNORM);
  frame.bind_image(frame_snapshot_ids_[1], next.layers.handle(), next.layers.view(),
                   VK_FORMAT_R16G16B16A16_SFLOAT);
  frame.bind_buffer(frame_snapshot_ids_[2], next.state.handle());
  if (runs_.started() == taken_ && !paused_ && (due_ || trial)) start(frame, !due_);
}

void PlacementBeside::adopt() {
  taken_ = runs_.started();
  adopted_slot_ = started_slot_;
  adopt_now_ = true;
  adopted_order_count_ = started_order_count_;
  adopted_frame_ = start_frame_;
  ++stats_.adopted;
  stats_.latency_frames.push_back(uint32_t(frame_ - start_frame_));
  timings_ = runner_->timings();
  placement_.readback().use_slot(*runner_, adopted_slot_);
}

// Records the next placement now (the placement's labels and order are this frame's) and submits
// it after the frame, which feeds it. Its results go to the readback slot the adopted placement's
// are not in.
void PlacementBeside::start(graph::GraphRunner& frame, bool trial) {
  const uint64_t k = runs_.started() + 1;
  start_now_ = true;
  trial_ = trial;
  if (!trial) due_ = false;
  started_slot_ = 1 - adopted_slot_;
  start_frame_ = frame_;
  started_order_count_ = placement_.order_count();
  const Snapshot& s = snapshots_[k % 2];
  runner_->bind_image(runner_snapshot_ids_[0], s.final.handle(), s.final.view(),
                      VK_FORMAT_R8G8B8A8_UNORM);
  runner_->bind_image(runner_snapshot_ids_[1], s.layers.handle(), s.layers.view(),
                      VK_FORMAT_R16G16B16A16_SFLOAT);
  runner_->bind_buffer(runner_snapshot_ids_[2], s.state.handle());
  placement_.readback().use_slot(*runner_, started_slot_);
  runs_.run_after(frame, *runner_);
  // (the host reads the adopted placement's results until this one is adopted)
  placement_.readback().use_slot(*runner_, adopted_slot_);
}

}  // namespace strata
