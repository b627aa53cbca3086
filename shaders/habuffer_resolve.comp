#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require

// The resolve of any scene (habuffer_resolve.glsl).
#include "habuffer_resolve.glsl"
