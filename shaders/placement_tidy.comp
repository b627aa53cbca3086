#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#include "shared/tidy_gpu.h"

// The tidy-up's steps but the search, for up to TIDY_SHARED_MAX (256) labels: each workgroup
// copies the labels' states into shared memory first.
#include "placement_tidy.glsl"
#include "placement_tidy_states_shared.glsl"
#include "placement_tidy_states_shared_steps.glsl"
#include "placement_tidy_round.glsl"
#include "placement_tidy_steps.glsl"
