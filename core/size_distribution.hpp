// Particle-size distributions given as discrete diameters with number or mass fractions
// (the paper: seven sizes, mean diameter 1.1 mm).
#pragma once

#include <cstdint>
#include <vector>

namespace fl {

struct SizeDistribution {
  enum class Basis { Number, Mass };
  std::vector<double> diameters;  // [m]
  std::vector<double> fractions;  // weights, normalised on use [-]
  Basis basis = Basis::Number;

  // Seven diameters 0.8..1.4 mm in equal number fractions: number-mean 1.1 mm (paper, "7 sizes, mean
  // 1.1 mm"; the individual sizes are not given there, this choice is documented in the README).
  static SizeDistribution paperGlassBeads();
  static SizeDistribution mono(double diameter) { return {{diameter}, {1.0}, Basis::Number}; }

  void validate() const;  // throws InputError
  // Number fractions regardless of basis (mass fraction w_k -> number fraction ∝ w_k / d_k^3).
  std::vector<double> numberFractions() const;
  double numberMeanDiameter() const;
};

// Radii of `count` particles: each size gets round(count * fraction) particles (largest remainder so
// the total is exact), then the list is shuffled with the seed. Deterministic for a seed.
std::vector<double> sampleRadii(const SizeDistribution& psd, int count, std::uint64_t seed);

}  // namespace fl
