// The soak (`strata bench soak`): the viewer's frame loop for many frames stays flat in memory and
// its HA-Buffer settles; and what ends a frame badly (an allocation the device cannot make, a
// wait for the GPU past its timeout) ends with one clear error, not a crash or a hang.
#include <doctest/doctest.h>

#include <chrono>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "engine/gpu/context.h"
#include "engine/gpu/resources.h"
#include "engine/gpu/vulkan_check.h"
#include "engine/graph/frame_slots.h"
#include "gpu_fixture.h"
#include "test_files.h"

namespace strata {
namespace {

// The demo head with two atlas regions as transparent surfaces: meshes, so the HA-Buffer holds
// fragments (head.json has none: its table is one slot).
std::filesystem::path surfaces_scene(const std::filesystem::path& folder) {
  const std::string cache = STRATA_SOURCE_DIR "/assets/cache/mricron/";
  return test::write_file(folder / "surfaces.json",
                          R"({"strata_scene": 1,
  "volumes": [{"name": "head", "file": ")" +
                              cache +
                              R"(ch2.nii.gz", "transfer_function": ")" STRATA_SOURCE_DIR
                              R"(/assets/transfer_functions/head-t1.json"}],
  "atlas": [{"labels": ")" + cache +
                              R"(aal.nii.gz", "names": ")" + cache + R"(aal.nii.txt",
             "regions": ["Precentral_L", "Frontal_Sup_L", "Thalamus_R"],
             "make": ["labels", "surfaces"]}],
  "camera": {"fov_y": 30, "near": 50, "far": 1200,
             "eye": [-260, -330, 160], "target": [0, 17, 19], "up": [0, 0, 1],
             "positions": [{"name": "front", "eye": [0, -480, 19], "target": [0, 17, 19],
                            "up": [0, 0, 1]}]}})");
}

}  // namespace

TEST_SUITE("cli") {
  // A short soak, validated: the HA-Buffer starts far too small (64 slots), grows in the first
  // half (the first zoom in) and then holds; host and device memory end within 1% of where the
  // warm-up left them.
  TEST_CASE("soak_keeps_memory_flat_and_the_habuffer_settles") {
    const auto folder = test::fresh_folder("soak", "flat");
    const std::string json = (folder / "soak.json").string();
    const auto r = test::run_strata("--validate bench soak " + surfaces_scene(folder).string() +
                                    " --frames 120 --size 64 --every 4 --interval 4"
                                    " --habuffer-slots 64 --json " +
                                    json);
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    CHECK(r.output.find("validation:") == std::string::npos);
    CHECK(r.output.find("soak: ok") != std::string::npos);
    const nlohmann::json report = nlohmann::json::parse(test::read_file(json));
    CHECK(report["ok"] == true);
    CHECK(report["frames"] == 120);
    // (the warm-up applies each of the schedule's changes once; the measured half repeats them)
    CHECK(report["warmup_frames"].get<int>() <= 60);
    CHECK(report["changes_applied"].get<int>() >= 5);
    CHECK(report["samples"].size() >= 12);
    // (VmRSS is reported, not judged: shared libraries' code pages come and go with it)
    CHECK(report["host_rss_bytes"]["start"].get<double>() >
          report["host_rss_anon_bytes"]["start"].get<double>());
    for (const char* key : {"host_rss_anon_bytes", "host_heap_bytes", "device_bytes"}) {
      CAPTURE(key);
      CHECK(report[key]["start"].get<double>() > 0.0);
      CHECK(report[key]["growth_percent"].get<double>() <= 1.0);
      CHECK(report[key]["peak"].get<double>() >= report[key]["end"].get<double>());
    }
    // Grown from the 64 slots asked for, in the first half only, and large enough at the end.
    const nlohmann::json& habuffer = report["habuffer"];
    CHECK(habuffer["slots"]["end"].get<double>() > 64.0);
    CHECK(habuffer["last_growth_frame"].get<int>() > 0);
    CHECK(habuffer["last_growth_frame"].get<int>() <= 60);
    CHECK(habuffer["fragments_end"].get<double>() > 0.0);
    CHECK(habuffer["load_end"].get<double>() <= 0.75);
  }

  // The HA-Buffer asked for more than the device allocates at once (lavapipe: 2 GiB) is refused
  // before any allocation, with the resource, the bytes and the limit named.
  TEST_CASE("an_habuffer_past_the_device_allocation_limit_is_one_error_naming_it") {
    const auto r = test::run_strata("--validate bench soak " STRATA_SOURCE_DIR
                                    "/assets/scenes/head.json --frames 20 --size 48"
                                    " --habuffer-slots 300000000");
    INFO(r.output);
    CHECK(r.exit_code == 1);
    CHECK(r.output.find("validation:") == std::string::npos);
    CHECK(r.output.find("strata: error: render graph: 'render.keys' for a 48x48 viewport: a "
                        "buffer of 2400000000 bytes is more than device 'llvmpipe") !=
          std::string::npos);
    CHECK(r.output.find("maxMemoryAllocationSize: 2147483648 bytes") != std::string::npos);
  }
}

TEST_SUITE("gpu") {
  // Strata's own device memory is counted (what `bench soak` reports), and an allocation over
  // the device's limits is an Error naming the limit, not a driver failure.
  TEST_CASE("device_memory_is_counted_and_past_the_limits_refused_by_name") {
    test::GpuTest t;
    const DeviceMemoryUse before = t.ctx.memory_use();
    {
      Buffer buffer(t.ctx, 1 << 20, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryKind::device_local);
      Image image(
          t.ctx,
          {VK_FORMAT_R8G8B8A8_UNORM, {64, 64, 1}, VK_IMAGE_TYPE_2D, VK_IMAGE_USAGE_STORAGE_BIT});
      const DeviceMemoryUse during = t.ctx.memory_use();
      CHECK(during.bytes >= before.bytes + (1 << 20) + 64 * 64 * 4);
      CHECK(during.allocations == before.allocations + 2);
      CHECK(during.peak >= during.bytes);
    }
    CHECK(t.ctx.memory_use().bytes == before.bytes);
    CHECK(t.ctx.memory_use().allocations == before.allocations);

    REQUIRE(t.ctx.max_allocation() < t.ctx.max_buffer());  // (lavapipe: 2 GiB, 4 GiB - 1)
    const VkDeviceSize too_big = t.ctx.max_allocation() + 4096;
    const std::string message = test::error_of([&] {
      Buffer b(t.ctx, too_big, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryKind::device_local);
    });
    CHECK(message.find("a buffer of " + std::to_string(too_big) + " bytes is more than device") !=
          std::string::npos);
    CHECK(message.find("maxMemoryAllocationSize") != std::string::npos);
    CHECK(t.ctx.memory_use().bytes == before.bytes);
  }

  // A frame the GPU has not finished when the timeout runs out is a GpuTimeout naming the frame,
  // not a wait without end: real work (1 GiB of fills on lavapipe), waited for with no time
  // at all. Then the wait with time finishes it and the context is no longer taken as hung.
  TEST_CASE("a_frame_not_finished_within_the_gpu_timeout_is_an_error_naming_it") {
    test::GpuTest t;
    const auto timeout = t.ctx.gpu_timeout();
    {
      constexpr VkDeviceSize part = 128u << 20;
      Buffer target(t.ctx, 8 * part, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryKind::device_local);
      FrameSlots slots(t.ctx, 2);
      const uint32_t slot = slots.next();
      const VkCommandBuffer cmd = slots.begin(slot);
      for (uint32_t i = 0; i < 8; ++i) vkCmdFillBuffer(cmd, target.handle(), i * part, part, i);
      slots.submit(slot);
      t.ctx.set_gpu_timeout(std::chrono::nanoseconds(0));
      std::string message;
      try {
        slots.wait_all();
        message = "(finished at once)";
      } catch (const GpuTimeout& e) {
        message = e.what();
      }
      CHECK(message.find("the GPU did not finish frame 1 within 0 s (VK_TIMEOUT)") !=
            std::string::npos);
      CHECK(t.ctx.hung());
      t.ctx.set_gpu_timeout(timeout);
      slots.wait_all();
      CHECK(!t.ctx.hung());
    }
    CHECK(t.ctx.gpu_timeout() == timeout);
  }
}

}  // namespace strata
