// One lavapipe (or STRATA_DEVICE) context for the whole GPU test run, with the Khronos validation
// layer and synchronization validation on. Every GPU test uses GpuTest, which fails the test if the
// layer said anything while it ran.
#pragma once

#include <string>

#include <glm/glm.hpp>

#include "engine/gpu/context.h"
#include "engine/gpu/resources.h"
#include "engine/graph/render_graph.h"

namespace strata::test {

Context& gpu();

struct GpuTest {
  Context& ctx = gpu();
  GpuTest();
  ~GpuTest();
};

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

// Runs the strata binary built with these tests, with `args` (shell syntax), and captures it.
CommandResult run_strata(const std::string& args, const std::string& env = "");

// Depth layers as the renderer leaves them: an rgba16f 2D-array storage image of `layer_count`
// layers of `size`, from premultiplied colours (layer after layer, rows top to bottom), in the
// general layout.
Image layer_image(Context& ctx, graph::Extent size, uint32_t layer_count,
                  const std::vector<glm::vec4>& layers);

// What ffprobe (Debian's ffmpeg) says of a video file's first video stream: `entries` (e.g.
// "codec_name,width,height,nb_read_frames") as comma-separated values, frames counted.
std::string probe_video(const std::string& file, const std::string& entries);

// A folder for files the tests write (created on first use).
std::string output_dir();

// Two rgba8 images of `size` agree: at most 1% of the pixels differ by more than `tolerance` in
// some colour channel (the first `channels`: 4 compares alpha too). Otherwise the actual, expected
// and difference images go to output_dir() as NAME.actual.png, NAME.expected.png,
// NAME.difference.png.
void check_close(const std::vector<uint8_t>& actual, const std::vector<uint8_t>& expected,
                 graph::Extent size, const std::string& name, int tolerance = 3, int channels = 3);

}  // namespace strata::test
