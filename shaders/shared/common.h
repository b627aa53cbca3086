// Lets one header declare structs, constants and functions for both C++ and GLSL.
#ifndef STRATA_SHARED_COMMON_H
#define STRATA_SHARED_COMMON_H

#ifdef __cplusplus
#include <cstdint>

#include <glm/glm.hpp>

// The GLSL types and built-in functions the shared headers use, under their GLSL names. Each is
// taken from GLM by name: a using-directive would pour all of GLM into strata::gpu, where its
// other names could silently win overload resolution over strata's own.
namespace strata::gpu {
using uint = uint32_t;
using glm::ivec2;
using glm::ivec4;
using glm::mat3;
using glm::mat4;
using glm::uvec2;
using glm::uvec3;
using glm::uvec4;
using glm::vec2;
using glm::vec3;
using glm::vec4;

using glm::abs;
using glm::all;
using glm::ceil;
using glm::clamp;
using glm::dot;
using glm::floatBitsToUint;
using glm::floor;
using glm::greaterThanEqual;
using glm::inversesqrt;
using glm::length;
using glm::lessThanEqual;
using glm::max;
using glm::min;
using glm::mix;
using glm::normalize;
using glm::packHalf2x16;
using glm::packUnorm4x8;
using glm::pow;
using glm::sin;
using glm::smoothstep;
using glm::sqrt;
using glm::transpose;
using glm::uintBitsToFloat;
using glm::unpackHalf2x16;
using glm::unpackUnorm4x8;
}  // namespace strata::gpu

#define STRATA_BEGIN namespace strata::gpu {
#define STRATA_END }
// A function defined in a shared header is inline in C++, so that every file may include it;
// GLSL has no such keyword.
#define STRATA_INLINE inline
// A member's value in a C++ aggregate initialised without it; GLSL structs have none.
#define STRATA_DEFAULT(value) = value
#else
#define STRATA_BEGIN
#define STRATA_END
#define STRATA_INLINE
#define STRATA_DEFAULT(value)
#endif

#endif
