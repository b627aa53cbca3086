#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require

// The resolve of a scene of one volume and no meshes (habuffer_resolve.glsl).
#define VR_RESOLVE_ONE_VOLUME
#include "habuffer_resolve.glsl"
