#include "passes/summed_area_table.h"

#include "engine/graph/graph_runner.h"
#include "shared/summed_area_table.h"

namespace strata {

using graph::ResourceId;
using graph::Use;

namespace {

gpu::SatParams params_for(graph::Extent e, uint32_t layers = 1) {
  return {.width = e.width,
          .height = e.height,
          .tiles_x = group_count(e.width, SAT_TILE),
          .tiles_y = group_count(e.height, SAT_TILE),
          .layers = layers};
}

}  // namespace

SummedAreaTable::SummedAreaTable(Context& ctx)
    : sums_(ctx, "summed_area_table_sums.comp"),
      carries_(ctx, "summed_area_table_carries.comp"),
      scan_(ctx, "summed_area_table_scan.comp") {}

void SummedAreaTable::add_to(graph::Graph& graph, ResourceId input, ResourceId output,
                             const std::string& group, uint32_t layers) const {
  const ResourceId carries = graph.add_buffer(
      group + ".carries", {[layers](graph::Extent e) {
        const gpu::SatParams p = params_for(e);
        return (VkDeviceSize{p.tiles_x} * e.height + VkDeviceSize{p.tiles_y} * e.width) *
               sizeof(float) * layers;
      }});

  // The three passes differ only in pipeline, resources and workgroup count.
  const auto add = [&](const char* name, const ComputePipeline& pipeline,
                       std::vector<graph::ResourceUse> uses, bool per_tile) {
    graph.add_pass({group + "." + name, graph::PassKind::compute, std::move(uses),
                    [&pipeline, per_tile, layers](graph::PassContext& pc) {
                      const gpu::SatParams p = params_for(pc.viewport, layers);
                      if (per_tile) {
                        pc.dispatch_groups(pipeline, p, {p.tiles_x, p.tiles_y, layers});
                      } else {  // a thread per image row and column, per layer
                        pc.dispatch(pipeline, p, {p.width + p.height, layers, 1});
                      }
                    },
                    group});
  };
  add("sums", sums_,
      {{input, Use::storage_read, SAT_BINDING_INPUT},
       {carries, Use::storage_write, SAT_BINDING_CARRIES}},
      true);
  add("carries", carries_, {{carries, Use::storage_read_write, SAT_BINDING_CARRIES}}, false);
  add("scan", scan_,
      {{input, Use::storage_read, SAT_BINDING_INPUT},
       {carries, Use::storage_read, SAT_BINDING_CARRIES},
       {output, Use::storage_write, SAT_BINDING_OUTPUT}},
      true);
}

std::vector<double> summed_area_table_reference(std::span<const float> values, uint32_t width,
                                                uint32_t height) {
  std::vector<double> out(size_t{width} * height);
  for (uint32_t y = 0; y < height; ++y) {
    double row = 0.0;
    for (uint32_t x = 0; x < width; ++x) {
      const size_t i = size_t{y} * width + x;
      row += values[i];
      out[i] = row + (y > 0 ? out[i - width] : 0.0);
    }
  }
  return out;
}

}  // namespace strata
