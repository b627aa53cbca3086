#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#include "shared/tidy_gpu.h"

// The tidy-up's search step for up to TIDY_SHARED_MAX (256) labels, with the shared memory only
// it needs.
#include "placement_tidy.glsl"
#include "placement_tidy_states_shared.glsl"
#include "placement_tidy_states_shared_search.glsl"
#include "placement_tidy_round.glsl"
#include "placement_tidy_search.glsl"
