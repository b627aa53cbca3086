#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#include "shared/tidy_gpu.h"

// The tidy-up's search step for more than TIDY_SHARED_MAX (256) labels: the labels' states are
// read from the buffer.
#include "placement_tidy.glsl"
#include "placement_tidy_states_buffer.glsl"
#include "placement_tidy_round.glsl"
#include "placement_tidy_search.glsl"
