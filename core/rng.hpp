// Seeded random numbers whose sequence is identical on every platform and standard library:
// SplitMix64 (Steele, Lea & Flood 2014). std::uniform_real_distribution is implementation-defined,
// so it is not used where results must be reproducible from a seed.
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace fl {

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : m_state(seed) {}

  std::uint64_t nextU64() {
    std::uint64_t z = (m_state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  // Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(nextU64() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }

  std::uint64_t state() const { return m_state; }
  void setState(std::uint64_t s) { m_state = s; }

 private:
  std::uint64_t m_state;
};

// Fisher–Yates shuffle driven by rng (std::shuffle's use of the generator is implementation-defined):
// the same permutation for a seed on every platform.
template <class T>
void shuffle(std::vector<T>& a, Rng& rng) {
  for (std::size_t i = a.size(); i > 1; --i) std::swap(a[i - 1], a[rng.nextU64() % i]);
}

}  // namespace fl
