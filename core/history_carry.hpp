// The contact history's carry-over across a neighbour-list rebuild, inside the history's own array.
// Each new pair takes the history of the old pair with the same key (i, j, image - image_j + image_i), the image
// counters those of each list's time (the old list's before the rebuild wrapped the particles); an old pair
// carries only a history that is not zero. Both lists are sorted by (i, j), so one merge finds the matches, and
// they are monotone: old pairs q < q' go to new pairs p < p'. So the entries can be moved inside one array: those
// that move down in increasing order, then those that move up in decreasing order; none overwrites an entry still
// to be moved (an old entry at a slot written by a downward move itself moves further down, and was moved first;
// likewise upward); the slots no old pair reaches are zeroed last. A rebuild then needs no second history
// array, and writes no fresh memory (huge_pages.hpp: fitCapacity; docs/performance.md, fortieth session).
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "contact_store.hpp"
#include "huge_pages.hpp"
#include "types.hpp"

namespace fl {

// The definition of a list's pairs, and the particles' image counters of its time.
struct PairKeys {
  const HugeVector<std::int32_t>& first;
  const HugeVector<std::int32_t>& second;
  const HugeVector<Image>& image;
  const std::vector<Vec3i>& particleImage;
};

// match[p] = 1 + the old pair whose history new pair p takes, else 0; `oldHistory` is the old list's, read for
// which pairs carry one.
void matchHistory(const PairKeys& oldPairs, const HugeVector<ContactHistory>& oldHistory, const PairKeys& newPairs,
                  HugeVector<std::uint32_t>& match);

// Moves each old entry of h to the new pair that matches it, zeroes the others, and leaves h with match.size()
// entries. h holds the old list's entries on entry (one per old pair).
template <class H>
void moveHistory(HugeVector<H>& h, const HugeVector<std::uint32_t>& match) {
  const std::size_t count = match.size();
  fitCapacity(h, std::max(h.size(), count));
  if (h.size() < count) h.resize(count);
  for (std::size_t p = 0; p < count; ++p)  // downward, in increasing order
    if (match[p] != 0 && match[p] - 1 > p) h[p] = h[match[p] - 1];
  for (std::size_t p = count; p-- > 0;)  // upward, in decreasing order
    if (match[p] != 0 && match[p] - 1 < p) h[p] = h[match[p] - 1];
  for (std::size_t p = 0; p < count; ++p)
    if (match[p] == 0) h[p] = H{};
  h.resize(count);
}

}  // namespace fl
