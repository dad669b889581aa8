#include "contact_store.hpp"

namespace fl {

std::size_t ContactStore::activeCount() const {
  std::size_t n = 0;
  for (double d : overlap) n += d > 0.0;
  return n;
}

void ContactStore::resizeResults() {
  const std::size_t n = size();
  normal.assign(n, Vec3::Zero());
  overlap.assign(n, 0.0);
  distance.assign(n, 0.0);
  normalForce.assign(n, 0.0);
  force.assign(n, Vec3::Zero());
  kick.assign(n, KickTerms{});
}

void ContactStore::deriveKickTerms() {
  kick.assign(size(), KickTerms{});
  for (std::size_t p = 0; p < size(); ++p)
    if (overlap[p] > 0.0) kick[p] = {force[p], normal[p].cross(force[p]), 0.5 * overlap[p]};
}

void ContactStore::buildAdjacency(std::size_t particleCount) {
  adjStart.assign(particleCount + 1, 0);
  for (std::size_t p = 0; p < size(); ++p) {
    ++adjStart[first[p] + 1];
    ++adjStart[second[p] + 1];
  }
  for (std::size_t k = 0; k < particleCount; ++k) adjStart[k + 1] += adjStart[k];
  adjEntry.resize(2 * size());
  std::vector<std::int32_t> fill(adjStart.begin(), adjStart.end() - 1);
  for (std::size_t p = 0; p < size(); ++p) {
    adjEntry[fill[first[p]]++] = static_cast<std::int32_t>(p << 1);
    adjEntry[fill[second[p]]++] = static_cast<std::int32_t>((p << 1) | 1);
  }
}

}  // namespace fl
