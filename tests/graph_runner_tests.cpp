// The runner's side of "declared is used": a pass gets only the resources it declared, and the
// dependent dispatches of one pass are ordered by the graph's barrier helper (synchronization
// validation shows that they must be). A graph on the second queue runs where its timelines put it.
#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <random>

#include "engine/core/error.h"
#include "engine/gpu/resources.h"
#include "engine/graph/frame_slots.h"
#include "engine/graph/graph_runner.h"
#include "engine/graph/second_queue.h"
#include "gpu_fixture.h"
#include "passes/summed_area_table.h"
#include "shared/summed_area_table.h"

namespace strata {
namespace {

bool has_hazard(const std::vector<std::string>& messages) {
  for (const std::string& m : messages) {
    if (m.find("SYNC-HAZARD") != std::string::npos) return true;
  }
  return false;
}

// The summed-area table's three dispatches in one pass, with or without the barrier helper
// between them; returns the table.
std::vector<float> table_in_one_pass(Context& ctx, const std::vector<float>& values,
                                     graph::Extent size, bool barriers) {
  const VkDeviceSize bytes = values.size() * sizeof(float);
  Buffer input(ctx, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryKind::device_local);
  Buffer output(ctx, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryKind::device_local);
  upload(ctx, input, as_bytes(values));
  const ComputePipeline sums(ctx, "summed_area_table_sums.comp");
  const ComputePipeline carries(ctx, "summed_area_table_carries.comp");
  const ComputePipeline scan(ctx, "summed_area_table_scan.comp");
  const gpu::SatParams p{size.width,
                         size.height,
                         group_count(size.width, SAT_TILE),
                         group_count(size.height, SAT_TILE),
                         1,
                         0,
                         0,
                         0};

  graph::Graph g;
  const auto in = g.import_buffer("input", {.buffer = input.handle(), .has_content = true});
  const auto out =
      g.import_buffer("output", {.buffer = output.handle(), .final_use = graph::Use::transfer_src});
  const auto carry = g.add_buffer(
      "carries", {[p](graph::Extent e) {
        return (VkDeviceSize{p.tiles_x} * e.height + VkDeviceSize{p.tiles_y} * e.width) * 4;
      }});
  g.add_pass({"table",
              graph::PassKind::compute,
              {{in, graph::Use::storage_read, SAT_BINDING_INPUT},
               {carry, graph::Use::storage_write, SAT_BINDING_CARRIES},  // (made here)
               {out, graph::Use::storage_write, SAT_BINDING_OUTPUT}},
              [&](graph::PassContext& pc) {
                pc.dispatch_groups(sums, p, {p.tiles_x, p.tiles_y, 1});
                if (barriers) pc.barrier();
                pc.dispatch(carries, p, {p.width + p.height, 1, 1});
                if (barriers) pc.barrier();
                pc.dispatch_groups(scan, p, {p.tiles_x, p.tiles_y, 1});
                // (the scan again, which changes nothing: the same pipeline after a barrier)
                if (barriers) pc.barrier();
                pc.dispatch_groups(scan, p, {p.tiles_x, p.tiles_y, 1});
              }});
  graph::GraphRunner runner(ctx, std::move(g));
  runner.set_viewport(size);
  runner.run_now();
  return download_as<float>(ctx, output);
}

// A viewport's worth of values in [0, 1).
std::vector<float> random_values(graph::Extent size, uint32_t seed) {
  std::vector<float> values(size_t{size.width} * size.height);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> dist(0.0f, 1.0f);
  for (float& v : values) v = dist(rng);
  return values;
}

graph::BufferInfo small_buffer() {
  return {[](graph::Extent) { return VkDeviceSize{64}; }};
}

// A transfer pass that declares `declared` and zeroes `touched`.
graph::PassInfo fill(const char* name, graph::ResourceId declared, graph::ResourceId touched) {
  return {name,
          graph::PassKind::transfer,
          {{declared, graph::Use::transfer_dst}},
          [touched](graph::PassContext& pc) {
            vkCmdFillBuffer(pc.cmd, pc.buffer(touched), 0, VK_WHOLE_SIZE, 0);
          }};
}

// Records `g` on the test device and expects the graph error `message`.
void check_recording_fails(Context& ctx, graph::Graph g, const char* message) {
  graph::GraphRunner runner(ctx, std::move(g));
  runner.set_viewport({4, 4});
  CHECK_THROWS_WITH_AS(runner.run_now(), message, graph::GraphError);
}

}  // namespace

TEST_SUITE("gpu") {
  // A conditional block's dispatches run only where the predicate an earlier pass wrote is not 0
  // (the graph's barrier makes the write visible to the predicate's read: synchronization
  // validation would say otherwise): a block per dispatch, or one across the pass's barriers.
  // A block must not stay open.
  TEST_CASE_FIXTURE(test::GpuTest, "conditional_blocks_run_only_where_their_predicate_is_set") {
    REQUIRE(ctx.conditional_rendering());  // (lavapipe and NVIDIA's driver have it)
    const graph::Extent size{16, 8};
    const std::vector<float> ones(size_t{size.width} * size.height, 1.0f);
    const gpu::SatParams p{size.width, size.height, 1, 1, 1, 0, 0, 0};
    const ComputePipeline sums(ctx, "summed_area_table_sums.comp");
    const ComputePipeline carries(ctx, "summed_area_table_carries.comp");
    const ComputePipeline scan(ctx, "summed_area_table_scan.comp");
    for (const auto& [predicate, per_dispatch] :
         {std::pair{0u, true}, std::pair{7u, true}, std::pair{0u, false}, std::pair{7u, false}}) {
      CAPTURE(predicate);
      CAPTURE(per_dispatch);
      const VkDeviceSize bytes = ones.size() * sizeof(float);
      Buffer input(ctx, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryKind::device_local);
      Buffer output(ctx, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryKind::device_local);
      upload(ctx, input, as_bytes(ones));
      upload(ctx, output, as_bytes(std::vector<float>(ones.size(), -1.0f)));
      graph::Graph g;
      const auto in = g.import_buffer("input", {.buffer = input.handle(), .has_content = true});
      const auto out = g.import_buffer(
          "output",
          {.buffer = output.handle(), .has_content = true, .final_use = graph::Use::transfer_src});
      const auto carry = g.add_buffer("carries", small_buffer());
      const auto flag = g.add_buffer("predicate", small_buffer());
      g.add_pass({"predicate",
                  graph::PassKind::transfer,
                  {{flag, graph::Use::transfer_dst}},
                  [&](graph::PassContext& pc) {
                    vkCmdFillBuffer(pc.cmd, pc.buffer(flag), 0, VK_WHOLE_SIZE, predicate);
                  }});
      g.add_pass({"table",
                  graph::PassKind::compute,
                  {{in, graph::Use::storage_read, SAT_BINDING_INPUT},
                   {carry, graph::Use::storage_write, SAT_BINDING_CARRIES},
                   {out, graph::Use::storage_read_write, SAT_BINDING_OUTPUT},
                   {flag, graph::Use::conditional}},
                  [&](graph::PassContext& pc) {
                    pc.begin_conditional(flag, 4);
                    pc.dispatch_groups(sums, p, {1, 1, 1});
                    if (per_dispatch) pc.end_conditional();
                    pc.barrier();
                    if (per_dispatch) pc.begin_conditional(flag, 0);
                    pc.dispatch(carries, p, {p.width + p.height, 1, 1});
                    if (per_dispatch) pc.end_conditional();
                    pc.barrier();
                    if (per_dispatch) pc.begin_conditional(flag, 8);
                    pc.dispatch_groups(scan, p, {1, 1, 1});
                    pc.end_conditional();
                  }});
      graph::GraphRunner runner(ctx, std::move(g));
      runner.set_viewport(size);
      runner.run_now();
      const std::vector<float> table = download_as<float>(ctx, output);
      CHECK(table.front() == (predicate != 0 ? 1.0f : -1.0f));
      CHECK(table.back() == (predicate != 0 ? float(ones.size()) : -1.0f));
    }

    // Misuse is a graph error naming the pass.
    const auto conditional_pass =
        [&](const char* name, graph::Use use,
            std::function<void(graph::PassContext&, graph::ResourceId)> record) {
          graph::Graph g;
          const auto flag = g.add_buffer("predicate", small_buffer());
          g.add_pass(fill("zero", flag, flag));
          g.add_pass({name,
                      graph::PassKind::compute,
                      {{flag, use}},
                      [flag, record](graph::PassContext& pc) { record(pc, flag); }});
          return g;
        };
    check_recording_fails(ctx,
                          conditional_pass("undeclared", graph::Use::storage_read,
                                           [](graph::PassContext& pc, graph::ResourceId f) {
                                             pc.begin_conditional(f, 0);
                                           }),
                          "pass 'undeclared' reads a predicate from 'predicate', which it did not "
                          "declare conditional");
    check_recording_fails(ctx,
                          conditional_pass("nested", graph::Use::conditional,
                                           [](graph::PassContext& pc, graph::ResourceId f) {
                                             pc.begin_conditional(f, 0);
                                             pc.begin_conditional(f, 0);
                                           }),
                          "pass 'nested' begins a conditional block inside another");
    check_recording_fails(ctx,
                          conditional_pass("open", graph::Use::conditional,
                                           [](graph::PassContext& pc, graph::ResourceId f) {
                                             pc.begin_conditional(f, 0);
                                           }),
                          "pass 'open' leaves a conditional block open");
  }

  TEST_CASE_FIXTURE(test::GpuTest, "a_pass_that_touches_a_resource_it_did_not_declare_fails") {
    graph::Graph g;
    const auto declared = g.add_buffer("declared", small_buffer());
    const auto hidden = g.add_buffer("hidden", small_buffer());
    g.add_pass(fill("fill", declared, hidden));
    check_recording_fails(ctx, std::move(g),
                          "pass 'fill' touches 'hidden', which it did not declare");
  }

  TEST_CASE_FIXTURE(test::GpuTest, "an_indirect_dispatch_needs_an_indirect_declaration") {
    const ComputePipeline tidy(ctx, "placement_tidy.comp");
    graph::Graph g;
    const auto args = g.add_buffer("args", small_buffer());
    g.add_pass(fill("zero", args, args));
    g.add_pass({"dispatch",
                graph::PassKind::compute,
                {{args, graph::Use::storage_read}},
                [&](graph::PassContext& pc) { pc.dispatch_indirect(tidy, 0u, args, 0); }});
    check_recording_fails(
        ctx, std::move(g),
        "pass 'dispatch' dispatches from 'args', which it did not declare indirect");
  }

  TEST_CASE_FIXTURE(test::GpuTest, "dependent_dispatches_in_one_pass_are_ordered_by_its_barriers") {
    const graph::Extent size{70, 45};
    const std::vector<float> values = random_values(size, 5);
    const std::vector<double> cpu = summed_area_table_reference(values, size.width, size.height);

    const auto worst_error = [&](const std::vector<float>& gpu) {
      double worst = 0.0;
      for (size_t i = 0; i < gpu.size(); ++i) {
        worst = std::max(worst, std::abs(gpu[i] - cpu[i]) / std::max(1.0, cpu[i]));
      }
      return worst;
    };
    CHECK(worst_error(table_in_one_pass(ctx, values, size, true)) < 1e-5);
    CHECK(ctx.validation_log().count() == 0);

    // The same dispatches without the helper's barriers: a read-after-write hazard.
    table_in_one_pass(ctx, values, size, false);
    CHECK(has_hazard(ctx.validation_log().take()));
  }

  // A frame run a range of passes at a time, a submission each (work that returns to the host
  // between passes), does what one run does: the barriers before each range's first pass come
  // with it, and every pass has its timings.
  TEST_CASE_FIXTURE(test::GpuTest, "a_graph_run_in_ranges_of_passes_matches_one_run") {
    const graph::Extent size{70, 45};
    const std::vector<float> values = random_values(size, 7);
    const VkDeviceSize bytes = values.size() * sizeof(float);
    Buffer input(ctx, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryKind::device_local);
    upload(ctx, input, as_bytes(values));
    const SummedAreaTable tables(ctx);
    const auto table = [&](bool in_ranges) {
      Buffer output(ctx, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryKind::device_local);
      graph::Graph g;
      const auto in = g.import_buffer("input", {.buffer = input.handle(), .has_content = true});
      const auto out = g.import_buffer(
          "output", {.buffer = output.handle(), .final_use = graph::Use::transfer_src});
      tables.add_to(g, in, out);  // (three passes, each reading what the one before wrote)
      graph::GraphRunner runner(ctx, std::move(g));
      REQUIRE(runner.graph().passes().size() == 3);
      runner.set_viewport(size);
      if (in_ranges) {
        runner.run_passes(0, 1);
        runner.run_passes(1, 1);  // (nothing)
        runner.run_passes(1, 3);
      } else {
        runner.run_now();
      }
      CHECK(runner.timings().size() == 3);
      CHECK_THROWS_AS(runner.run_passes(2, 4), Error);
      return download_as<float>(ctx, output);
    };
    const std::vector<float> whole = table(false);
    CHECK(table(true) == whole);
    const std::vector<double> cpu = summed_area_table_reference(values, size.width, size.height);
    CHECK(whole.back() == doctest::Approx(cpu.back()).epsilon(1e-5));
    CHECK(ctx.validation_log().count() == 0);
  }

  // The hand-off of the placement beside the frames: a run on the second queue reads what the
  // frame that started it wrote, and a later frame that waits for it reads what it wrote; only
  // the timelines order them (the host waits here only to read the results).
  TEST_CASE_FIXTURE(test::GpuTest,
                    "a_second_queue_run_follows_its_frame_and_precedes_the_one_waiting") {
    constexpr VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                         VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                         VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    const auto buffer = [&] { return Buffer(ctx, 4, usage, MemoryKind::device_local, true); };
    const Buffer fed = buffer(), result = buffer(), seen = buffer();
    upload(ctx, result, as_bytes(std::vector<uint32_t>{0}));

    graph::Graph run;  // the second queue's: result = fed
    const auto run_fed = run.import_buffer("fed", {.buffer = fed.handle(), .has_content = true});
    const auto run_result = run.import_buffer("result", {.buffer = result.handle()});
    run.add_pass({"copy",
                  graph::PassKind::transfer,
                  {{run_fed, graph::Use::transfer_src}, {run_result, graph::Use::transfer_dst}},
                  [=](graph::PassContext& pc) { pc.copy_buffer(run_fed, run_result, 4); }});
    graph::GraphRunner second(ctx, std::move(run));
    second.set_viewport({1, 1});

    uint32_t value = 0;
    graph::Graph g;  // a frame's: fed = value, seen = result
    const auto g_fed = g.import_buffer("fed", {.buffer = fed.handle()});
    const auto g_result =
        g.import_buffer("result", {.buffer = result.handle(), .has_content = true});
    const auto g_seen =
        g.import_buffer("seen", {.buffer = seen.handle(), .final_use = graph::Use::transfer_src});
    g.add_pass({"write",
                graph::PassKind::transfer,
                {{g_fed, graph::Use::transfer_dst}},
                [&](graph::PassContext& pc) {
                  record_update(pc.cmd, pc.buffer(g_fed), 0, std::as_bytes(std::span(&value, 1)));
                }});
    g.add_pass({"read",
                graph::PassKind::transfer,
                {{g_result, graph::Use::transfer_src}, {g_seen, graph::Use::transfer_dst}},
                [=](graph::PassContext& pc) { pc.copy_buffer(g_result, g_seen, 4); }});
    graph::GraphRunner frame(ctx, std::move(g));
    frame.set_viewport({1, 1});

    FrameSlots slots(ctx, 1);
    graph::SecondQueue queue(ctx);
    const auto run_frame = [&](uint32_t written, const std::function<void()>& hand_off) {
      value = written;
      const uint32_t slot = slots.next();
      frame.submission() = {};
      hand_off();
      frame.record(slots.begin(slot), slot);
      const graph::FrameSubmission& submission = frame.submission();
      slots.submit(slot, submission.wait, submission.signal);
      if (submission.submitted) submission.submitted();
      slots.wait_all();
    };
    run_frame(7, [&] { CHECK(queue.run_after(frame, second) == 1); });
    CHECK(download_as<uint32_t>(ctx, seen) == std::vector<uint32_t>{0});  // (before the run)
    queue.wait_idle();
    CHECK(queue.started() == 1);
    CHECK(queue.finished(1));
    CHECK_FALSE(queue.finished(2));
    run_frame(8, [&] { queue.wait_in(frame, 1); });
    CHECK(download_as<uint32_t>(ctx, seen) == std::vector<uint32_t>{7});
    CHECK(download_as<uint32_t>(ctx, result) == std::vector<uint32_t>{7});
    CHECK(ctx.validation_log().count() == 0);
  }
}

}  // namespace strata
