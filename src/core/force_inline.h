// For the per-ray setup and tests of the traversal hot loops: g++ otherwise
// sometimes emits them as calls returning a struct through memory, a large
// part of a coherent ray's time.
#pragma once

#define HPRT_FORCE_INLINE inline __attribute__((always_inline))
