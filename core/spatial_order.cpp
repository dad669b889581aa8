#include "spatial_order.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "errors.hpp"

namespace fl {

namespace {
// Spreads the low 10 bits of v so that two zero bits follow each one (bit k moves to bit 3k).
std::uint32_t spread3(std::uint32_t v) {
  v &= 0x3FFu;
  v = (v | (v << 16)) & 0x030000FFu;
  v = (v | (v << 8)) & 0x0300F00Fu;
  v = (v | (v << 4)) & 0x030C30C3u;
  v = (v | (v << 2)) & 0x09249249u;
  return v;
}

std::uint32_t quantise(double s) {
  s -= std::floor(s);  // wrap into [0, 1)
  const double q = std::floor(s * 1024.0);
  return static_cast<std::uint32_t>(std::clamp(q, 0.0, 1023.0));  // callers pass finite s only
}

template <class T, class A>
void permute(std::vector<T, A>& a, const std::vector<std::size_t>& order) {
  std::vector<T, A> out;
  out.reserve(a.size());
  for (std::size_t k : order) out.push_back(a[k]);
  a.swap(out);
}
}  // namespace

std::uint32_t mortonCode(const Vec3& reduced) {
  std::uint32_t c[3];
  for (int k = 0; k < 3; ++k) c[k] = std::isfinite(reduced[k]) ? quantise(reduced[k]) : 0u;
  return spread3(c[0]) | (spread3(c[1]) << 1) | (spread3(c[2]) << 2);
}

std::vector<std::size_t> mortonOrder(const ParticleStore& particles, const PeriodicCell& cell) {
  const std::size_t n = particles.size();
  std::vector<std::uint64_t> key(n);
  for (std::size_t i = 0; i < n; ++i)
    key[i] = (static_cast<std::uint64_t>(mortonCode(cell.reduced(particles.pos[i]))) << 32) | i;
  std::sort(key.begin(), key.end());
  std::vector<std::size_t> order(n);
  for (std::size_t k = 0; k < n; ++k) order[k] = static_cast<std::size_t>(key[k] & 0xFFFFFFFFu);
  return order;
}

void reorderParticles(ParticleStore& p, const std::vector<std::size_t>& order) {
  const std::size_t n = p.size();
  if (order.size() != n)
    throw InputError("reorderParticles: order has " + std::to_string(order.size()) + " entries for " +
                     std::to_string(n) + " particles");
  std::vector<char> seen(n, 0);
  for (std::size_t k : order) {
    if (k >= n || seen[k]) throw InputError("reorderParticles: order is not a permutation of 0.." + std::to_string(n - 1));
    seen[k] = 1;
  }
  permute(p.pos, order);
  permute(p.vel, order);
  permute(p.angVel, order);
  permute(p.force, order);
  permute(p.torque, order);
  permute(p.radius, order);
  permute(p.invMass, order);
  permute(p.invInertia, order);
  permute(p.id, order);
  permute(p.material, order);
  permute(p.image, order);
}

void sortSpatially(ParticleStore& particles, const PeriodicCell& cell) {
  reorderParticles(particles, mortonOrder(particles, cell));
}

}  // namespace fl
