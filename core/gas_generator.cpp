#include "gas_generator.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "errors.hpp"
#include "rng.hpp"

namespace fl {

Packing generateGas(const GasSpec& spec) {
  if (!(spec.solidFraction > 0.0 && spec.solidFraction <= 0.4)) {
    std::ostringstream s;
    s << "gas generator: solidFraction must be in (0, 0.4], got " << spec.solidFraction
      << " (random sequential addition jams near 0.38; compress to densify)";
    throw InputError(s.str());
  }
  std::vector<double> radii = sampleRadii(spec.sizes, spec.count, spec.seed);
  std::stable_sort(radii.begin(), radii.end(), std::greater<double>());
  double solid = 0.0;
  for (double r : radii) solid += 4.0 / 3.0 * kPi * r * r * r;
  const double L = std::cbrt(solid / spec.solidFraction);
  Packing out{ParticleStore{}, PeriodicCell::box(L, L, L)};
  const double rmax = radii.front();
  const int nb = std::max(1, static_cast<int>(std::floor(L / (2.0 * rmax))));
  const double binSize = L / nb;
  std::vector<std::vector<int>> bins(static_cast<std::size_t>(nb) * nb * nb);
  auto binIndex = [&](int x, int y, int z) {
    x = (x % nb + nb) % nb;
    y = (y % nb + nb) % nb;
    z = (z % nb + nb) % nb;
    return (static_cast<std::size_t>(z) * nb + y) * nb + x;
  };
  Rng rng(spec.seed ^ 0xA5A5A5A5ULL);
  const int maxTries = 200000;
  for (double r : radii) {
    bool placed = false;
    for (int t = 0; t < maxTries && !placed; ++t) {
      const Vec3 x(rng.uniform() * L, rng.uniform() * L, rng.uniform() * L);
      const int bx = static_cast<int>(x.x() / binSize), by = static_cast<int>(x.y() / binSize),
                bz = static_cast<int>(x.z() / binSize);
      bool ok = true;
      for (int dz = -1; dz <= 1 && ok; ++dz)
        for (int dy = -1; dy <= 1 && ok; ++dy)
          for (int dx = -1; dx <= 1 && ok; ++dx)
            for (int j : bins[binIndex(bx + dx, by + dy, bz + dz)]) {
              Vec3 d = out.particles.pos[j] - x;
              for (int k = 0; k < 3; ++k) d[k] -= L * std::round(d[k] / L);  // minimum image
              const double rc = r + out.particles.radius[j];
              if (d.squaredNorm() < rc * rc) { ok = false; break; }
            }
      if (!ok) continue;
      bins[binIndex(bx, by, bz)].push_back(static_cast<int>(out.particles.size()));
      out.particles.add(x, r, spec.density, spec.material);
      placed = true;
    }
    if (!placed) {
      std::ostringstream s;
      s << "gas generator: could not place particle " << out.particles.size() + 1 << " of " << spec.count
        << " at solidFraction " << spec.solidFraction << "; lower solidFraction";
      throw InputError(s.str());
    }
  }
  return out;
}

}  // namespace fl
