#include "contact_store.hpp"

namespace fl {

std::size_t ContactStore::activeCount() const {
  std::size_t n = 0;
  for (const PairResult& r : result) n += r.overlap > 0.0;
  return n;
}

void ContactStore::resizeResults() {
  result.clear();
  fitCapacity(result, size());  // reused by each rebuild (huge_pages.hpp)
  result.assign(size(), PairResult{});
}

void ContactStore::markTouched() {
  touched.assign((size() + 63) / 64, 0);
  for (std::size_t p = 0; p < size(); ++p)
    if (history[p].contactRadius != 0.0) touched[p / 64] |= std::uint64_t{1} << (p % 64);
  touchedValid = true;
}

void ContactStore::buildAdjacency(std::size_t particleCount) {
  // counted, summed, then filled with adjStart as the cursor and shifted back: no array beside the store's (a
  // rebuild touches no fresh memory, docs/performance.md, fortieth session)
  adjStart.assign(particleCount + 1, 0);
  for (std::size_t p = 0; p < size(); ++p) {
    ++adjStart[first[p] + 1];
    ++adjStart[second[p] + 1];
  }
  for (std::size_t k = 0; k < particleCount; ++k) adjStart[k + 1] += adjStart[k];
  adjEntry.clear();
  fitCapacity(adjEntry, 2 * size());
  adjEntry.resize(2 * size());
  for (std::size_t p = 0; p < size(); ++p) {
    adjEntry[adjStart[first[p]]++] = static_cast<std::int32_t>(p << 1);
    adjEntry[adjStart[second[p]]++] = static_cast<std::int32_t>((p << 1) | 1);
  }
  for (std::size_t k = particleCount; k > 0; --k) adjStart[k] = adjStart[k - 1];
  adjStart[0] = 0;
}

}  // namespace fl
