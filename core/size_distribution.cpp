#include "size_distribution.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "errors.hpp"
#include "rng.hpp"

namespace fl {

SizeDistribution SizeDistribution::paperGlassBeads() {
  SizeDistribution p;
  for (int k = 0; k < 7; ++k) p.diameters.push_back((0.8 + 0.1 * k) * 1e-3);
  p.fractions.assign(7, 1.0 / 7.0);
  return p;
}

void SizeDistribution::validate() const {
  if (diameters.empty()) throw InputError("size distribution: 'diameters' must list at least one size");
  if (diameters.size() != fractions.size())
    throw InputError("size distribution: 'fractions' must have as many entries as 'diameters' (" +
                     std::to_string(diameters.size()) + "), got " + std::to_string(fractions.size()));
  for (double d : diameters)
    if (!(d > 0.0 && std::isfinite(d))) throw InputError("size distribution: every diameter must be > 0 m");
  double sum = 0.0;
  for (double f : fractions) {
    if (!(f >= 0.0 && std::isfinite(f))) throw InputError("size distribution: fractions must be >= 0");
    sum += f;
  }
  if (!(sum > 0.0)) throw InputError("size distribution: fractions must not all be zero");
}

std::vector<double> SizeDistribution::numberFractions() const {
  std::vector<double> w(fractions);
  if (basis == Basis::Mass)
    for (std::size_t k = 0; k < w.size(); ++k) w[k] /= diameters[k] * diameters[k] * diameters[k];
  const double s = std::accumulate(w.begin(), w.end(), 0.0);
  for (double& x : w) x /= s;
  return w;
}

double SizeDistribution::numberMeanDiameter() const {
  const auto w = numberFractions();
  double m = 0.0;
  for (std::size_t k = 0; k < w.size(); ++k) m += w[k] * diameters[k];
  return m;
}

std::vector<double> sampleRadii(const SizeDistribution& psd, int count, std::uint64_t seed) {
  psd.validate();
  if (count < 1) throw InputError("particle count must be >= 1");
  const auto w = psd.numberFractions();
  const std::size_t K = w.size();
  std::vector<int> n(K);
  std::vector<std::pair<double, std::size_t>> rem;
  int total = 0;
  for (std::size_t k = 0; k < K; ++k) {
    const double exact = w[k] * count;
    n[k] = static_cast<int>(std::floor(exact));
    total += n[k];
    rem.push_back({exact - n[k], k});
  }
  std::stable_sort(rem.begin(), rem.end(), [](auto& a, auto& b) { return a.first > b.first; });
  for (int i = 0; total < count; ++i, ++total) ++n[rem[i % K].second];
  std::vector<double> radii;
  radii.reserve(count);
  for (std::size_t k = 0; k < K; ++k) radii.insert(radii.end(), n[k], 0.5 * psd.diameters[k]);
  Rng rng(seed);
  shuffle(radii, rng);
  return radii;
}

}  // namespace fl
