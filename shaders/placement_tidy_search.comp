#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#include "shared/tidy_gpu.h"

// The tidy-up's search phase for up to 256 labels, with the shared memory only it needs
// (placement_finalize.glsl).
#define TIDY_SEARCH_ONLY
#include "placement_finalize.glsl"
