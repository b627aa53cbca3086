#include "engine/graph/render_graph.h"

#include <algorithm>
#include <utility>

namespace strata::graph {
namespace {

constexpr VkPipelineStageFlags2 kShaderStages[] = {
    VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,                                           // compute
    VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,  // graphics
    VK_PIPELINE_STAGE_2_NONE,                                                         // transfer
};

bool image_only(Use use) {
  return use == Use::sampled || use == Use::color_attachment || use == Use::color_blend ||
         use == Use::depth_attachment || use == Use::present;
}

bool buffer_only(Use use) {
  return use == Use::uniform || use == Use::indirect || use == Use::conditional ||
         use == Use::host_read;
}

VkFlags usage_flag(Use use, bool is_image) {
  switch (use) {
    case Use::sampled:
      return VK_IMAGE_USAGE_SAMPLED_BIT;
    case Use::storage_read:
    case Use::storage_write:
    case Use::storage_read_write:
      return is_image ? VkFlags{VK_IMAGE_USAGE_STORAGE_BIT}
                      : VkFlags{VK_BUFFER_USAGE_STORAGE_BUFFER_BIT};
    case Use::uniform:
      return VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT;
    case Use::indirect:
      return VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT;
    case Use::conditional:
      return VK_BUFFER_USAGE_CONDITIONAL_RENDERING_BIT_EXT;
    case Use::color_attachment:
    case Use::color_blend:
      return VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
    case Use::depth_attachment:
      return VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
    case Use::transfer_src:
      return is_image ? VkFlags{VK_IMAGE_USAGE_TRANSFER_SRC_BIT}
                      : VkFlags{VK_BUFFER_USAGE_TRANSFER_SRC_BIT};
    case Use::transfer_dst:
      return is_image ? VkFlags{VK_IMAGE_USAGE_TRANSFER_DST_BIT}
                      : VkFlags{VK_BUFFER_USAGE_TRANSFER_DST_BIT};
    case Use::host_read:
    case Use::present:
      return 0;
  }
  return 0;
}

// The synchronisation state of one resource as the passes are walked in order.
struct State {
  bool has_content = false;
  VkPipelineStageFlags2 write_stage = VK_PIPELINE_STAGE_2_NONE;  // last write (or transition)
  VkAccessFlags2 write_access = VK_ACCESS_2_NONE;
  VkPipelineStageFlags2 read_stages = VK_PIPELINE_STAGE_2_NONE;     // reads since that write
  VkPipelineStageFlags2 visible_stages = VK_PIPELINE_STAGE_2_NONE;  // made visible since then
  VkAccessFlags2 visible_access = VK_ACCESS_2_NONE;
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
};

// Advances `state` over one access and returns the barrier it needs, if any: read after write,
// write after read, write after write, and layout transitions (which count as writes).
std::optional<Barrier> step(State& state, const Access& a, ResourceId id, bool is_image) {
  const bool transition = is_image && a.layout != state.layout;
  Barrier b{id, is_image};
  b.dst_stage = a.stage;
  b.dst_access = a.access;
  b.old_layout = state.has_content ? state.layout : VK_IMAGE_LAYOUT_UNDEFINED;
  b.new_layout = is_image ? a.layout : VK_IMAGE_LAYOUT_UNDEFINED;

  if (a.writes || transition) {
    b.src_stage = state.write_stage | state.read_stages;
    b.src_access = state.write_access;  // after reads, an execution dependency is enough
    const bool needed = transition || b.src_stage != VK_PIPELINE_STAGE_2_NONE;
    // A transition happens before this pass's accesses, which see its result.
    state.write_stage = a.stage;
    state.write_access = a.writes
                             ? (a.access & ~VkAccessFlags2{VK_ACCESS_2_SHADER_STORAGE_READ_BIT |
                                                           VK_ACCESS_2_SHADER_SAMPLED_READ_BIT |
                                                           VK_ACCESS_2_TRANSFER_READ_BIT})
                             : VK_ACCESS_2_NONE;
    state.read_stages = a.reads ? a.stage : VK_PIPELINE_STAGE_2_NONE;
    // Nothing has seen this pass's own writes yet; a bare transition is seen by this pass.
    state.visible_stages = a.writes ? VK_PIPELINE_STAGE_2_NONE : a.stage;
    state.visible_access = a.writes ? VK_ACCESS_2_NONE : a.access;
    state.layout = b.new_layout;
    state.has_content = state.has_content || a.writes;
    return needed ? std::optional(b) : std::nullopt;
  }
  // A read with no transition: wait for the last write unless a barrier already covers it.
  state.read_stages |= a.stage;
  const bool covered =
      (state.visible_stages & a.stage) == a.stage && (state.visible_access & a.access) == a.access;
  if (state.write_stage == VK_PIPELINE_STAGE_2_NONE || covered) return std::nullopt;
  b.src_stage = state.write_stage;
  b.src_access = state.write_access;
  state.visible_stages |= a.stage;
  state.visible_access |= a.access;
  return b;
}

// One pass may name a resource more than once (say, as two bindings): merge into one access.
struct MergedUse {
  ResourceId resource;
  Access access;
  Use first_use;
  // Reads content from before the pass: every read, but predicates (Use::conditional) of a
  // resource the pass writes itself, which it reads after writing them.
  bool needs_content = false;
  bool predicates = false;
};

std::vector<MergedUse> merge_uses(const PassInfo& pass, const Graph& graph) {
  std::vector<MergedUse> merged;
  std::vector<uint32_t> bindings;
  for (const ResourceUse& u : pass.uses) {
    if (u.resource >= graph.resources().size()) {
      throw GraphError("pass '" + pass.name + "' uses resource #" + std::to_string(u.resource) +
                       ", which the graph does not have");
    }
    const ResourceInfo& r = graph.resources()[u.resource];
    if ((r.is_image && buffer_only(u.use)) || (!r.is_image && image_only(u.use)) ||
        u.use == Use::host_read || u.use == Use::present) {
      throw GraphError("pass '" + pass.name + "' cannot use " + (r.is_image ? "image" : "buffer") +
                       " '" + r.name + "' as " + to_string(u.use));
    }
    if (u.binding) {
      const uint32_t slot = (*u.binding << 16) | u.array_element;
      if (std::find(bindings.begin(), bindings.end(), slot) != bindings.end()) {
        throw GraphError("pass '" + pass.name + "' binds two resources to binding " +
                         std::to_string(*u.binding));
      }
      bindings.push_back(slot);
    }
    const Access a = access_of(u.use, pass.kind, r.is_image);
    auto it = std::find_if(merged.begin(), merged.end(),
                           [&](const MergedUse& m) { return m.resource == u.resource; });
    const bool predicates = u.use == Use::conditional;
    if (it == merged.end()) {
      merged.push_back({u.resource, a, u.use, a.reads && !predicates, predicates});
      continue;
    }
    it->needs_content = it->needs_content || (a.reads && !predicates);
    it->predicates = it->predicates || predicates;
    if (r.is_image && it->access.layout != a.layout) {
      throw GraphError("pass '" + pass.name + "' uses image '" + r.name + "' in two layouts (as " +
                       to_string(it->first_use) + " and as " + to_string(u.use) + ")");
    }
    it->access.stage |= a.stage;
    it->access.access |= a.access;
    it->access.reads = it->access.reads || a.reads;
    it->access.writes = it->access.writes || a.writes;
  }
  for (MergedUse& m : merged) {
    if (m.predicates && !m.access.writes) m.needs_content = true;
  }
  return merged;
}

}  // namespace

const char* to_string(Use use) {
  switch (use) {
    case Use::sampled:
      return "sampled";
    case Use::storage_read:
      return "storage_read";
    case Use::storage_write:
      return "storage_write";
    case Use::storage_read_write:
      return "storage_read_write";
    case Use::uniform:
      return "uniform";
    case Use::indirect:
      return "indirect";
    case Use::conditional:
      return "conditional";
    case Use::color_attachment:
      return "color_attachment";
    case Use::color_blend:
      return "color_blend";
    case Use::depth_attachment:
      return "depth_attachment";
    case Use::transfer_src:
      return "transfer_src";
    case Use::transfer_dst:
      return "transfer_dst";
    case Use::host_read:
      return "host_read";
    case Use::present:
      return "present";
  }
  return "?";
}

Access access_of(Use use, PassKind kind, bool is_image) {
  const VkPipelineStageFlags2 shader = kShaderStages[static_cast<int>(kind)];
  const VkImageLayout general = is_image ? VK_IMAGE_LAYOUT_GENERAL : VK_IMAGE_LAYOUT_UNDEFINED;
  switch (use) {
    case Use::sampled:
      return {shader, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
              true, false};
    case Use::storage_read:
      return {shader, VK_ACCESS_2_SHADER_STORAGE_READ_BIT, general, true, false};
    case Use::storage_write:
      return {shader, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, general, false, true};
    case Use::storage_read_write:
      return {shader, VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
              general, true, true};
    case Use::uniform:
      return {shader, VK_ACCESS_2_UNIFORM_READ_BIT, VK_IMAGE_LAYOUT_UNDEFINED, true, false};
    case Use::indirect:
      return {VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT, VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT,
              VK_IMAGE_LAYOUT_UNDEFINED, true, false};
    case Use::conditional:
      return {VK_PIPELINE_STAGE_2_CONDITIONAL_RENDERING_BIT_EXT,
              VK_ACCESS_2_CONDITIONAL_RENDERING_READ_BIT_EXT, VK_IMAGE_LAYOUT_UNDEFINED, true,
              false};
    case Use::color_attachment:
      return {VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
              VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
              VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, false, true};
    case Use::color_blend:
      return {VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
              VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
              VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, true, true};
    case Use::depth_attachment:
      return {VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                  VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
              VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                  VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
              VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, false, true};
    case Use::transfer_src:
      return {VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT,
              is_image ? VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL : VK_IMAGE_LAYOUT_UNDEFINED, true,
              false};
    case Use::transfer_dst:
      return {VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
              is_image ? VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL : VK_IMAGE_LAYOUT_UNDEFINED, false,
              true};
    case Use::host_read:
      return {VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
              true, false};
    case Use::present:
      return {VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, true,
              false};
  }
  return {};
}

ResourceId Graph::add_image(std::string name, ImageInfo info) {
  ResourceInfo r{std::move(name), true, false};
  r.image = info;
  resources_.push_back(std::move(r));
  return static_cast<ResourceId>(resources_.size() - 1);
}

ResourceId Graph::add_buffer(std::string name, BufferInfo info) {
  ResourceInfo r{std::move(name), false, false};
  r.buffer = std::move(info);
  resources_.push_back(std::move(r));
  return static_cast<ResourceId>(resources_.size() - 1);
}

ResourceId Graph::import_buffer(std::string name, BufferImport info) {
  ResourceInfo r{std::move(name), false, true};
  r.import = {info.has_content, VK_IMAGE_LAYOUT_UNDEFINED, info.final_use};
  r.imported_buffer = info;
  resources_.push_back(std::move(r));
  return static_cast<ResourceId>(resources_.size() - 1);
}

ResourceId Graph::import_image(std::string name, ImageImport info) {
  ResourceInfo r{std::move(name), true, true};
  r.import = {info.has_content, info.initial_layout, info.final_use, info.initial_stage};
  r.imported_image = info;
  resources_.push_back(std::move(r));
  return static_cast<ResourceId>(resources_.size() - 1);
}

PassId Graph::add_pass(PassInfo pass) {
  passes_.push_back(std::move(pass));
  return static_cast<PassId>(passes_.size() - 1);
}

CompiledGraph compile(const Graph& graph) {
  const auto& resources = graph.resources();
  std::vector<State> states(resources.size());
  for (size_t i = 0; i < resources.size(); ++i) {
    if (!resources[i].imported) continue;
    states[i].has_content = resources[i].import.has_content;
    states[i].layout = resources[i].import.initial_layout;
    states[i].write_stage = resources[i].import.initial_stage;
  }

  CompiledGraph out;
  out.usage.assign(resources.size(), 0);
  out.kept_layout.assign(resources.size(), VK_IMAGE_LAYOUT_UNDEFINED);
  // A kept image starts each run as the last run left it: its one layout, after its last use.
  for (const PassInfo& pass : graph.passes()) {
    for (const MergedUse& m : merge_uses(pass, graph)) {
      const ResourceInfo& r = resources[m.resource];
      if (r.imported || !r.is_image || !r.image.keep) continue;
      State& s = states[m.resource];
      if (s.has_content && s.layout != m.access.layout) {
        throw GraphError("kept image '" + r.name + "' is used in two layouts");
      }
      s.has_content = true;
      s.layout = m.access.layout;
      s.write_stage = m.access.stage;
      out.kept_layout[m.resource] = m.access.layout;
    }
  }
  for (const PassInfo& pass : graph.passes()) {
    std::vector<Barrier> barriers;
    std::vector<VkImageLayout> layouts(resources.size(), VK_IMAGE_LAYOUT_UNDEFINED);
    for (const ResourceUse& u : pass.uses) {
      if (u.resource < resources.size()) {
        out.usage[u.resource] |= usage_flag(u.use, resources[u.resource].is_image);
      }
    }
    for (const MergedUse& m : merge_uses(pass, graph)) {
      const ResourceInfo& r = resources[m.resource];
      if (m.needs_content && !states[m.resource].has_content) {
        throw GraphError("pass '" + pass.name + "' reads '" + r.name +
                         "', which no earlier pass writes and which is not imported with content");
      }
      if (auto b = step(states[m.resource], m.access, m.resource, r.is_image))
        barriers.push_back(*b);
      layouts[m.resource] = m.access.layout;
    }
    out.pass_barriers.push_back(std::move(barriers));
    out.layout.push_back(std::move(layouts));
  }

  for (size_t i = 0; i < resources.size(); ++i) {
    const ResourceInfo& r = resources[i];
    if (!r.imported || !r.import.final_use) continue;
    if (!states[i].has_content) {
      throw GraphError("'" + r.name + "' must be handed on as " + to_string(*r.import.final_use) +
                       ", but no pass writes it");
    }
    out.usage[i] |= usage_flag(*r.import.final_use, r.is_image);
    const Access a = access_of(*r.import.final_use, PassKind::transfer, r.is_image);
    if (auto b = step(states[i], a, static_cast<ResourceId>(i), r.is_image)) {
      out.final_barriers.push_back(*b);
    }
  }
  return out;
}

namespace {

// The names of the pipeline stages set in `stages`, joined by '|'.
std::string stage_names(VkPipelineStageFlags2 stages) {
  static constexpr std::pair<VkPipelineStageFlags2, const char*> names[] = {
      {VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, "compute"},
      {VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, "graphics"},
      {VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT, "indirect"},
      {VK_PIPELINE_STAGE_2_CONDITIONAL_RENDERING_BIT_EXT, "conditional"},
      {VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, "transfer"},
      {VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, "color"},
      {VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
       "depth"},
      {VK_PIPELINE_STAGE_2_HOST_BIT, "host"}};
  std::string out;
  for (const auto& [bits, name] : names) {
    if ((stages & bits) == 0) continue;
    out += (out.empty() ? "" : "|") + std::string(name);
    stages &= ~bits;
  }
  if (stages != 0) out += (out.empty() ? "" : "|") + std::string("other");
  return out.empty() ? "none" : out;
}

const char* layout_name(VkImageLayout layout) {
  static constexpr std::pair<VkImageLayout, const char*> names[] = {
      {VK_IMAGE_LAYOUT_UNDEFINED, "undefined"},
      {VK_IMAGE_LAYOUT_GENERAL, "general"},
      {VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, "color_attachment"},
      {VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, "depth_attachment"},
      {VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, "shader_read_only"},
      {VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, "transfer_src"},
      {VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, "transfer_dst"},
      {VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, "present_src"}};
  for (const auto& [value, name] : names) {
    if (value == layout) return name;
  }
  return "other";
}

std::string describe_barrier(const Graph& graph, const Barrier& b) {
  std::string out = "    barrier '" + graph.resources()[b.resource].name +
                    "': " + stage_names(b.src_stage) + " -> " + stage_names(b.dst_stage);
  // (what the pass then does with the resource is its use, listed below the barriers)
  if (b.src_access == VK_ACCESS_2_NONE) out += ", execution only";
  if (b.is_image && b.old_layout != b.new_layout) {
    out +=
        std::string(", layout ") + layout_name(b.old_layout) + " -> " + layout_name(b.new_layout);
  }
  return out + "\n";
}

}  // namespace

std::string describe(const Graph& graph, const CompiledGraph& compiled) {
  static constexpr const char* kinds[] = {"compute", "graphics", "transfer"};
  std::string out;
  for (size_t p = 0; p < graph.passes().size(); ++p) {
    const PassInfo& pass = graph.passes()[p];
    out += "pass " + std::to_string(p) + " '" + pass.name + "' (" +
           kinds[static_cast<int>(pass.kind)] + (pass.group.empty() ? "" : ", " + pass.group) +
           ")\n";
    for (const Barrier& b : compiled.pass_barriers[p]) out += describe_barrier(graph, b);
    for (const ResourceUse& u : pass.uses) {
      out += "    uses '" + graph.resources()[u.resource].name + "' as " + to_string(u.use);
      if (u.binding) out += " at binding " + std::to_string(*u.binding);
      out += "\n";
    }
  }
  out += "after the last pass\n";
  for (const Barrier& b : compiled.final_barriers) out += describe_barrier(graph, b);
  out += std::to_string(graph.passes().size()) + " passes, " +
         std::to_string(barrier_count(compiled)) + " barriers\n";
  return out;
}

size_t barrier_count(const CompiledGraph& compiled) {
  size_t count = compiled.final_barriers.size();
  for (const auto& barriers : compiled.pass_barriers) count += barriers.size();
  return count;
}

}  // namespace strata::graph
