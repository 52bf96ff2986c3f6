// For the per-ray setup and tests of the traversal hot loops: g++ otherwise
// sometimes emits them as calls returning a struct through memory, which
// costs a quarter of a primary ray's time (measured on bvh8, 82k-triangle
// sphere: 85 -> 67 ns/ray).
#pragma once

#define HPRT_FORCE_INLINE inline __attribute__((always_inline))
