// Lets one header declare structs and constants for both C++ and GLSL.
#ifndef STRATA_SHARED_COMMON_H
#define STRATA_SHARED_COMMON_H

#ifdef __cplusplus
#include <cstdint>
#define STRATA_BEGIN namespace strata::gpu { using uint = uint32_t;
#define STRATA_END }
#else
#define STRATA_BEGIN
#define STRATA_END
#endif

#endif
