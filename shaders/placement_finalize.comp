#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#include "shared/tidy_gpu.h"

// The layout tidy-up for up to TIDY_SHARED_MAX (256) labels: each workgroup reads the labels'
// states into shared memory first (placement_finalize.glsl).
#include "placement_finalize.glsl"
