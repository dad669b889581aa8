#include "history_carry.hpp"

namespace fl {

void matchHistory(const PairKeys& old, const HugeVector<ContactHistory>& oldHistory, const PairKeys& now,
                  HugeVector<std::uint32_t>& match) {
  const std::size_t count = now.first.size(), oldCount = old.first.size();
  match.clear();
  fitCapacity(match, count);
  match.resize(count, 0);
  const auto carries = [&](std::size_t r) {
    return oldHistory[r].tangentialForce.squaredNorm() != 0.0 || oldHistory[r].contactRadius != 0.0;
  };
  std::size_t q = 0;
  for (std::size_t p = 0; p < count && q < oldCount; ++p) {
    const int i = now.first[p], j = now.second[p];
    while (q < oldCount && (old.first[q] < i || (old.first[q] == i && old.second[q] < j))) ++q;
    for (std::size_t r = q; r < oldCount && old.first[r] == i && old.second[r] == j; ++r) {
      if (!carries(r)) continue;
      const Vec3i key = now.image[p].vec() - now.particleImage[j] + now.particleImage[i];
      const Vec3i oldKey = old.image[r].vec() - old.particleImage[j] + old.particleImage[i];
      if (key == oldKey) {
        match[p] = static_cast<std::uint32_t>(r + 1);
        break;
      }
    }
  }
}

}  // namespace fl
