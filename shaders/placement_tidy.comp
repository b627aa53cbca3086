#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#include "shared/tidy_gpu.h"

// The tidy-up (shared/tidy.h) and the placements' output, one phase per dispatch
// (params.phase; params.step: the round): its start from the label loop's (cost, pixel) results,
// four dispatches per round, and each label's placement (box centre, cost, shown). A round whose
// round before applied nothing leaves at once. The changes a round applies are taken up by the
// next round's conflicts step (each label's workgroup stores its own; every workgroup reads the
// others' as `take` says), or by the output: a fifth dispatch per round for that alone cost time
// on every round, even a round with nothing to do.
// One source, four pipelines (the shader table in CMakeLists.txt): TIDY_SEARCH compiles the
// search step (placement_tidy_search.glsl) instead of the others (placement_tidy_steps.glsl), and
// TIDY_STATES_SHARED reads the labels' states from a copy in shared memory, up to TIDY_SHARED_MAX
// labels, instead of from the buffer (placement_tidy_states_*.glsl):
//   placement_tidy.comp               the steps but the search, states in shared memory
//   placement_tidy_large.comp         the same past TIDY_SHARED_MAX labels, states in the buffer
//   placement_tidy_search.comp        the search step, states in shared memory
//   placement_tidy_search_large.comp  the search step, states in the buffer
// (The search in a pipeline of its own: one pipeline for all steps took lavapipe twice as long to
// create, and on a GPU registers are allocated for a pipeline's largest step.)
layout(local_size_x = 64) in;
layout(binding = PLACEMENT_BINDING_TABLES, std430) readonly buffer Tables { float tables[]; };
layout(binding = PLACEMENT_BINDING_LABELS, std430) readonly buffer Labels { LabelGpu labels[]; };
layout(binding = PLACEMENT_BINDING_ORDER, std430) readonly buffer Order { uint order[]; };
layout(binding = PLACEMENT_BINDING_RESULTS, std430) readonly buffer Results { uint64_t results[]; };
layout(binding = PLACEMENT_BINDING_PLACEMENTS, std430) writeonly buffer Placements { PlacementGpu placements[]; };
layout(binding = PLACEMENT_BINDING_TIDY, std430) buffer Tidy { TidyGpu tidy[]; };
layout(binding = PLACEMENT_BINDING_TIDY_ROUNDS, std430) buffer Rounds { uint rounds[]; };
// The rounds' dispatch sizes where they are indirect (params.indirect: CPU devices): zero
// workgroups for a round after one that changed nothing. Untouched where the rounds are direct.
layout(binding = PLACEMENT_BINDING_TIDY_ARGS, std430) buffer Args { uint tidy_args[]; };

layout(binding = PLACEMENT_BINDING_KEEP_OUT, std430) readonly buffer KeepOut { uvec4 keep_out[]; };
layout(push_constant) uniform Push { PlacementParams params; };

// Round r runs: its steps' dispatch sizes, where they are indirect.
void write_round_args(uint r) {
  if (params.indirect == 0u) return;
  for (uint k = 0u; k < TIDY_ROUND_STEPS; ++k) {
    const uvec3 size = tidy_phase_groups(TIDY_PHASE_CONFLICTS + k, params.label_count);
    for (uint c = 0u; c < 3u; ++c) {
      // (every owner that applied a change writes the same sizes)
      atomicMax(tidy_args[(r * TIDY_ROUND_STEPS + k) * 3u + c], size[c]);
    }
  }
}

uvec4 keep_out_at(uint i) {
  return keep_out[i];
}
float table_at(uint layer, int x, int y) {
  if (x < 0 || y < 0) return 0.0f;
  return tables[(layer * params.height + uint(y)) * params.width + uint(x)];
}

#include "shared/tidy.h"

uint tidy_count() { return params.label_count; }
LabelGpu tidy_input(uint k) { return labels[k]; }
// (read once per change weighed, by one invocation: from the buffer in both shaders)
ivec4 tidy_conflicts_now(uint k) { return tidy[k].conflicts; }
// The conflicts step and the output see the changes the round before applied (TidyGpu::take).
bool tidy_takes(uint phase) { return phase == TIDY_PHASE_CONFLICTS || phase == TIDY_PHASE_OUTPUT; }

#ifdef TIDY_STATES_SHARED
#include "placement_tidy_states_shared.glsl"
#else
#include "placement_tidy_states_buffer.glsl"
#endif

// What the steps and the search share, once the states' accessors are defined.
#include "shared/tidy_search.h"

bool movable(uint k) {
  return (tidy_state(k).flags & (TIDY_PLACED | TIDY_MOVABLE)) == (TIDY_PLACED | TIDY_MOVABLE);
}

#ifdef TIDY_SEARCH
#include "placement_tidy_search.glsl"
#else
#include "placement_tidy_steps.glsl"
#endif
