#include "engine/core/gif_palette.h"

#include <cstring>
#include <vector>

#include "engine/core/error.h"

extern "C" {
#include <libavfilter/avfilter.h>
#include <libavfilter/buffersink.h>
#include <libavfilter/buffersrc.h>
#include <libavutil/frame.h>
}

namespace strata {
namespace {

struct GraphFree {
  void operator()(AVFilterGraph* graph) const { avfilter_graph_free(&graph); }
};
struct FrameFree {
  void operator()(AVFrame* frame) const { av_frame_free(&frame); }
};
using FilterGraph = std::unique_ptr<AVFilterGraph, GraphFree>;
using Frame = std::unique_ptr<AVFrame, FrameFree>;

// Ordered dithering: a pixel's pattern depends on its place only, so what stays still in the clip
// (labels, the background) stays the same from frame to frame, where error diffusion would let
// the moving parts' errors crawl into it.
constexpr const char* kPaletteUse = "dither=bayer:bayer_scale=3";

}  // namespace

struct GifPalette::Filters {
  std::string path;
  uint32_t width = 0, height = 0;
  size_t held_bytes = 0;
  std::vector<Frame> held;  // the frames the palette is made of, until it is
  FilterGraph mapping;      // paletteuse: frames and the palette in, PAL8 frames out
  AVFilterContext* frames_in = nullptr;
  AVFilterContext* mapped_out = nullptr;
  int64_t next_pts = 0;

  void check(int result, const char* what) const {
    if (result >= 0) return;
    char reason[AV_ERROR_MAX_STRING_SIZE] = {};
    av_strerror(result, reason, sizeof reason);
    throw Error(path + ": " + what + ": " + reason);
  }

  AVFilterContext* filter(AVFilterGraph* graph, const char* name, const std::string& args) const {
    AVFilterContext* context = nullptr;
    check(avfilter_graph_create_filter(&context, avfilter_get_by_name(name), name,
                                       args.empty() ? nullptr : args.c_str(), nullptr, graph),
          "setting up the GIF palette");
    return context;
  }

  // A frame source of `width` x `height` pixels of `format`, one frame a time-base unit.
  AVFilterContext* source(AVFilterGraph* graph, int w, int h, int format) const {
    return filter(graph, "buffer",
                  "video_size=" + std::to_string(w) + "x" + std::to_string(h) +
                      ":pix_fmt=" + std::to_string(format) + ":time_base=1/1:pixel_aspect=1/1");
  }

  void link(AVFilterContext* from, AVFilterContext* to, unsigned to_pad = 0) const {
    check(avfilter_link(from, 0, to, to_pad), "setting up the GIF palette");
  }

  Frame rgba_frame(std::span<const uint8_t> rgba) {
    Frame frame(av_frame_alloc());
    if (!frame) throw Error(path + ": out of memory");
    frame->format = AV_PIX_FMT_RGBA;
    frame->width = int(width);
    frame->height = int(height);
    check(av_frame_get_buffer(frame.get(), 0), "allocating a frame");
    const size_t row = size_t{width} * 4;
    for (uint32_t y = 0; y < height; ++y)
      std::memcpy(frame->data[0] + ptrdiff_t(y) * frame->linesize[0], rgba.data() + y * row, row);
    frame->pts = next_pts++;
    return frame;
  }

  // palettegen over the held frames: a 16 x 16 frame of the palette's colours.
  Frame make_palette() {
    FilterGraph graph(avfilter_graph_alloc());
    if (!graph) throw Error(path + ": out of memory");
    AVFilterContext* in = source(graph.get(), int(width), int(height), AV_PIX_FMT_RGBA);
    AVFilterContext* generate = filter(graph.get(), "palettegen", "");
    AVFilterContext* out = filter(graph.get(), "buffersink", "");
    link(in, generate);
    link(generate, out);
    check(avfilter_graph_config(graph.get(), nullptr), "setting up the GIF palette");
    for (const Frame& frame : held)
      check(av_buffersrc_add_frame_flags(in, frame.get(), AV_BUFFERSRC_FLAG_KEEP_REF),
            "making the GIF palette");
    check(av_buffersrc_add_frame(in, nullptr), "making the GIF palette");
    Frame palette(av_frame_alloc());
    if (!palette) throw Error(path + ": out of memory");
    check(av_buffersink_get_frame(out, palette.get()), "making the GIF palette");
    return palette;
  }

  // paletteuse with `palette` for the rest of the clip (the palette's input ends: it is kept).
  void start_mapping(Frame palette) {
    mapping.reset(avfilter_graph_alloc());
    if (!mapping) throw Error(path + ": out of memory");
    frames_in = source(mapping.get(), int(width), int(height), AV_PIX_FMT_RGBA);
    AVFilterContext* palette_in =
        source(mapping.get(), palette->width, palette->height, palette->format);
    AVFilterContext* use = filter(mapping.get(), "paletteuse", kPaletteUse);
    mapped_out = filter(mapping.get(), "buffersink", "");
    link(frames_in, use, 0);
    link(palette_in, use, 1);
    link(use, mapped_out);
    check(avfilter_graph_config(mapping.get(), nullptr), "setting up the GIF palette");
    palette->pts = 0;
    check(av_buffersrc_add_frame(palette_in, palette.get()), "making the GIF palette");
    check(av_buffersrc_add_frame(palette_in, nullptr), "making the GIF palette");
  }

  // Every mapped frame the filters have ready, to `out`.
  void drain(const FrameOut& out) {
    for (;;) {
      Frame mapped(av_frame_alloc());
      if (!mapped) throw Error(path + ": out of memory");
      const int result = av_buffersink_get_frame(mapped_out, mapped.get());
      if (result == AVERROR(EAGAIN) || result == AVERROR_EOF) return;
      check(result, "mapping a frame to the GIF palette");
      out(mapped.get());
    }
  }

  // `frame` (null: the end) to paletteuse, and what comes out to `out`.
  void map(AVFrame* frame, const FrameOut& out) {
    check(av_buffersrc_add_frame(frames_in, frame), "mapping a frame to the GIF palette");
    drain(out);
  }

  // The palette of the held frames, then those frames mapped.
  void map_held(const FrameOut& out) {
    start_mapping(make_palette());
    for (Frame& frame : held) map(frame.get(), out);
    held.clear();
  }
};

GifPalette::GifPalette(std::string path, uint32_t width, uint32_t height, size_t held_bytes)
    : filters_(std::make_unique<Filters>()) {
  filters_->path = std::move(path);
  filters_->width = width;
  filters_->height = height;
  filters_->held_bytes = held_bytes;
}

GifPalette::~GifPalette() = default;

void GifPalette::add(std::span<const uint8_t> rgba, const FrameOut& out) {
  Filters& f = *filters_;
  Frame frame = f.rgba_frame(rgba);
  if (f.mapping) {
    f.map(frame.get(), out);
    return;
  }
  f.held.push_back(std::move(frame));
  if (f.held.size() * rgba.size() >= f.held_bytes) f.map_held(out);
}

void GifPalette::finish(const FrameOut& out) {
  Filters& f = *filters_;
  if (!f.mapping) {
    if (f.held.empty()) return;
    f.map_held(out);
  }
  f.map(nullptr, out);
}

}  // namespace strata
