#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#include "shared/tidy_gpu.h"

// The tidy-up's search phase for more than 256 labels: the labels' states are read from the
// buffer (placement_finalize.glsl).
#define TIDY_STATES_IN_BUFFER
#define TIDY_SEARCH_ONLY
#include "placement_finalize.glsl"
