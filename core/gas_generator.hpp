// Seeded random loose "gas" of non-overlapping spheres in a cubic periodic cell at a chosen solid
// fraction (random sequential addition, largest first). The starting state of the paper's specimens.
#pragma once

#include <cstdint>

#include "particle_store.hpp"
#include "periodic_cell.hpp"
#include "size_distribution.hpp"

namespace fl {

struct GasSpec {
  int count = 4000;
  SizeDistribution sizes = SizeDistribution::paperGlassBeads();
  double solidFraction = 0.25;  // target solid volume / cell volume [-], allowed (0, 0.4]
  std::uint64_t seed = 1;
  double density = 2570.0;      // [kg/m^3]
  int material = 0;
};

struct Packing {
  ParticleStore particles;
  PeriodicCell cell;
};

// Throws InputError if the fraction is out of range or the insertion jams.
Packing generateGas(const GasSpec& spec);

}  // namespace fl
