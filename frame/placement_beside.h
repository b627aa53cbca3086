// The placement beside the frames. The placement (layers' costs, summed-area tables, the label
// loop, the tidy-up) runs in a graph of its own, submitted to Context::placement_queue() at its
// own pace, while every frame renders, moves the labels toward the targets of the newest finished
// placement and draws them, without waiting for a placement.
//
// A frame that finds the last placement finished adopts it (copies its targets, insertion order
// and the labels as it saw them into buffers the frames read) and starts the next one: it copies
// what the placement reads (the label-free final image, the layers, the forces' state) into a
// snapshot, and its submission signals the timeline the placement's submission waits for. There
// are two snapshots: the frames write only the one no placement reads. Each frame moves the
// adopted targets with the anchors (follow_anchor), so labels follow the camera in between.
//
// A trial placement (the viewer's optimisation on idle) runs the same way in another insertion
// order, but is never adopted: its results are read (take_trial) and the labels stay on the
// adopted placement's targets.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "engine/graph/graph_runner.h"
#include "engine/graph/second_queue.h"
#include "passes/label_forces.h"
#include "passes/placement.h"
#include "passes/volume_renderer.h"

namespace strata {

// The images a placement beside the frames reads, and the frame's that it copies them from.
struct SnapshotImages {
  graph::ResourceId final_image, layers;  // the frame's picture (rgba8) and layers (rgba16f)
  graph::ResourceId final_copy, layers_copy;
};

// The pass that copies the frame's picture and the first layers_now() of its layers, every texel
// as it is (placement_snapshot.comp), when the frame is recorded; 0: no copy in this frame.
void add_snapshot_pass(graph::Graph& graph, const ComputePipeline& pipeline,
                       const SnapshotImages& images, std::function<uint32_t()> layers_now);

class PlacementBeside {
 public:
  PlacementBeside(Context& ctx, Placement& placement, LabelForces& forces, uint32_t label_count);
  PlacementBeside(const PlacementBeside&) = delete;
  PlacementBeside& operator=(const PlacementBeside&) = delete;

  struct FrameIds {
    graph::ResourceId labels;   // LabelGpu[]: this frame's, with what they take from the last
    graph::ResourceId targets;  // PlacementGpu[]: the adopted placement's, moved into this frame
    graph::ResourceId order;    // uint[]: the adopted placement's insertion order
  };
  // The frame's side before its forces: the snapshot of the placement's images, the adoption,
  // this frame's labels (forces.previous on them) and the targets that follow the anchors.
  // `state`: the forces'.
  FrameIds add_to_frame(graph::Graph& graph, const VolumeRenderer::Outputs& rendered,
                        graph::ResourceId state);
  // After the frame's forces: the forces' `state` for the placement this frame starts (it holds
  // the targets of the placement the frame took up, as the frame after it would find them).
  void add_state_snapshot(graph::Graph& graph, graph::ResourceId state);
  // The placement's own graph, for `layer_count` layers of `size` (waits for a placement in
  // flight); the snapshots sized to match.
  void build(uint32_t layer_count, graph::Extent size);

  // Before the frame is recorded, with the frame's `labels` (Placement::set_frame was given them,
  // LabelForces::set_frame not yet): adopts a finished placement, starts the next one (a `trial`
  // where none is due and idle() held), and sets the frame's submission (its waits and signals,
  // and the placement's submission after it).
  void prepare(graph::GraphRunner& frame, const std::vector<gpu::LabelGpu>& labels,
               bool trial = false);
  // Whether the next frame may start a trial: no placement due, none in flight but a finished
  // trial, not paused.
  bool idle() const { return (runs_.started() == taken_ || trial_finished()) && !due_ && !paused_; }
  // The trial in flight has finished, and take_trial reads it.
  bool trial_finished() const { return trial_ && runs_.started() > taken_ && finished(); }
  // A finished trial taken up: `read` sees its results (the Placement's readback) and then the
  // readback is the adopted placement's again. False where no trial has finished.
  bool take_trial(const std::function<void()>& read);
  // Labels in the adopted placement's insertion order (the forces' keeping apart).
  uint32_t adopted_order_count() const { return adopted_order_count_; }
  // The frame that started the adopted placement (LabelledRenderer counts them from 1; 0: none
  // adopted yet).
  uint64_t adopted_frame() const { return adopted_frame_; }
  // The placement's own GPU time, of the adopted one.
  const std::vector<graph::PassTiming>& placement_timings() const { return timings_; }
  // Placements taken up so far, and the frames from each one's start to its take-up.
  struct Stats {
    uint64_t adopted = 0;
    std::vector<uint32_t> latency_frames;
  };
  const Stats& stats() const { return stats_; }
  // The frame being prepared (its number, counted by the caller).
  void set_frame_number(uint64_t frame) { frame_ = frame; }
  // While paused, no placement starts (one in flight is still taken up).
  void set_paused(bool paused) { paused_ = paused; }
  // Something the placement reads changed (the camera, the labels, the settings): the next
  // placement is due. Without a change since the last one started, none starts: at rest the
  // frames only move the labels to the last placement's targets.
  void set_due() { due_ = true; }
  // Waits for a placement in flight (at most the Context's GPU timeout).
  void wait_idle();

 private:
  struct Snapshot {
    Image final, layers;
    Buffer state;
  };
  bool finished() const;
  void adopt();
  void start(graph::GraphRunner& frame, bool trial);

  Context& ctx_;
  Placement& placement_;
  LabelForces& forces_;
  uint32_t label_count_;
  ComputePipeline snapshot_;  // the frame's copy for the placement it starts
  std::array<Snapshot, 2> snapshots_;
  Buffer published_targets_, published_labels_, published_order_;
  Buffer adopted_targets_, adopted_labels_, adopted_order_;
  std::unique_ptr<graph::GraphRunner> runner_;              // the placement's graph
  std::array<graph::ResourceId, 3> runner_snapshot_ids_{};  // final, layers, state
  std::array<graph::ResourceId, 3> frame_snapshot_ids_{};
  // Placement k is run k on the second queue, fed by the frame that wrote its snapshot.
  graph::SecondQueue runs_;
  uint64_t taken_ = 0;  // placements taken up (adopted, or read as a trial), counted from 1
  bool trial_ = false;  // the last placement started is a trial
  // The Placement's readback slots: the adopted placement's results, and the started one's.
  uint32_t adopted_slot_ = 0, started_slot_ = 0;
  uint64_t frame_ = 0, start_frame_ = 0, adopted_frame_ = 0;
  uint32_t layer_count_ = 1;
  uint32_t order_count_ = 0, adopted_order_count_ = 0, started_order_count_ = 0;
  bool adopt_now_ = false, start_now_ = false;  // what the frame being prepared does
  bool paused_ = false;
  bool due_ = true;
  std::vector<gpu::LabelGpu> frame_labels_;
  std::vector<graph::PassTiming> timings_;
  Stats stats_;
};

}  // namespace strata
