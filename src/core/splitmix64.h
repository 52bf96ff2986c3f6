// splitmix64 (Steele, Lea, Flood, "Fast splittable pseudorandom number
// generators", OOPSLA 2014): a 64-bit mixing function and the tiny generator
// built on it. Fully specified, so every platform draws the same numbers:
// generated meshes, ray sets, deformations and tree hashes depend on that.
#pragma once

#include <cstddef>
#include <cstdint>

namespace hprt {

// The generator's increment: 2^64 / golden ratio, odd.
inline constexpr uint64_t kSplitMixGamma = 0x9E3779B97F4A7C15ull;

// The finaliser: a bijection of 64-bit words that mixes every input bit into
// every output bit.
constexpr uint64_t splitmix64_mix(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// One step of the generator from state x: a well-mixed hash of x.
constexpr uint64_t splitmix64(uint64_t x) { return splitmix64_mix(x + kSplitMixGamma); }

class SplitMix64 {
 public:
  explicit constexpr SplitMix64(uint64_t seed) : state_(seed) {}
  constexpr uint64_t next() { return splitmix64_mix(state_ += kSplitMixGamma); }
  float uniform() { return float(next() >> 40) * 0x1.0p-24f; }  // [0, 1), 24 bits
  size_t below(size_t n) { return size_t(next() % n); }         // n > 0; bias negligible
  bool coin() { return (next() >> 63) != 0; }

 private:
  uint64_t state_;
};

}  // namespace hprt
