// The threads' shares and what crosses between them (thread_boundary.hpp).
#include "thread_boundary.hpp"

#include <algorithm>
#include <limits>

namespace fl {

ThreadBoundary buildThreadBoundary(const ContactStore& c, std::size_t particleCount, int threads,
                                   std::size_t chunk, bool halo, const std::vector<std::size_t>& edges) {
  ThreadBoundary b;
  const int nt = std::max(1, threads);
  const std::size_t n = particleCount, np = c.size();
  const std::size_t chunks = (np + chunk - 1) / chunk;
  b.threads = nt;
  b.begin.resize(nt + 1);
  b.chunkBegin.resize(nt + 1);
  // given edges of this list (a chunk each, ascending), else the static split
  bool given = edges.size() == static_cast<std::size_t>(nt) + 1 && edges.front() == 0 && edges.back() == chunks;
  for (int t = 0; given && t < nt; ++t) given = edges[t] < edges[t + 1];
  if (given) b.chunkBegin = edges;
  else for (int t = 0; t <= nt; ++t) b.chunkBegin[t] = staticBegin(t, nt, chunks);
  const bool aligned = nt > 1 && chunks >= static_cast<std::size_t>(nt);
  const bool exchange = aligned && halo;
  for (int t = 0; t <= nt; ++t)
    b.begin[t] = t == nt ? n
                 : !aligned ? staticBegin(t, nt, n)
                 : t == 0 ? 0
                          : static_cast<std::size_t>(c.first[chunk * b.chunkBegin[t]]);
  b.haloBegin.assign(nt + 1, 0);
  b.seedBegin.assign(nt + 1, 1);
  b.seedParticle.assign(1, -1);
  b.exchange = exchange;
  if (!exchange) return b;
  b.partner.assign(c.second.begin(), c.second.end());
  b.seedOf.assign(n, 0);
  b.kickBegin.assign(c.adjStart.begin(), c.adjStart.begin() + static_cast<std::ptrdiff_t>(n));

  std::vector<int> owner(n);
  for (int t = 0; t < nt; ++t)
    for (std::size_t i = b.begin[t]; i < b.begin[t + 1]; ++i) owner[i] = t;
  std::vector<int> passThread(chunks);
  for (int t = 0; t < nt; ++t)
    for (std::size_t k = b.chunkBegin[t]; k < b.chunkBegin[t + 1]; ++k) passThread[k] = t;
  const auto computedBy = [&](std::size_t p) { return passThread[p / chunk]; };

  // halo: the second particles that a pair's pass thread does not own (a first particle another thread owns
  // is read in place: only the first particle of a share can be one, for a few pairs). Slots are grouped by
  // owner, each group in the order of the pairs that first read them, so that the owner's copy fills them in the
  // order the readers' passes need them.
  std::vector<std::vector<std::int32_t>> group(nt);
  std::vector<std::int32_t> slot(n, -1);  // first its place in its owner's group
  for (std::size_t p = 0; p < np; ++p) {
    const int j = c.second[p], o = owner[j];
    if (o == computedBy(p) || slot[j] >= 0) continue;
    slot[j] = static_cast<std::int32_t>(group[o].size());
    group[o].push_back(j);
  }
  for (int t = 0; t < nt; ++t) {
    b.haloBegin[t] = b.halo.size();
    b.halo.insert(b.halo.end(), group[t].begin(), group[t].end());
  }
  b.haloBegin[nt] = b.halo.size();
  const std::size_t blocks = (np + ThreadBoundary::kHaloBlock - 1) / ThreadBoundary::kHaloBlock;
  b.haloPairs.assign(blocks, 0);
  b.haloNeed.assign(blocks, 0);
  for (std::size_t p = 0; p < np; ++p) {
    const int j = c.second[p];
    if (owner[j] == computedBy(p)) continue;
    const std::size_t block = p / ThreadBoundary::kHaloBlock;
    b.partner[p] = static_cast<std::int32_t>(n + b.haloBegin[owner[j]]) + slot[j];
    b.haloPairs[block] |= std::uint64_t{1} << (p % ThreadBoundary::kHaloBlock);
    b.haloNeed[block] = std::max(b.haloNeed[block], static_cast<std::uint32_t>(slot[j]) + 1);
  }
  // the pass prefetches the next block's halo slots while it computes this one
  for (std::size_t k = 0; k + 1 < blocks; ++k) b.haloNeed[k] = std::max(b.haloNeed[k], b.haloNeed[k + 1]);

  // seeds: a particle whose leading adjacency entries were all computed by one other thread (entries are in
  // pair order, and a share's pairs come after those of the shares before it, so the foreign ones lead)
  std::vector<std::vector<std::int32_t>> seeds(nt);
  for (std::size_t i = 0; i < n; ++i) {
    const int self = owner[i];
    const std::int32_t e0 = c.adjStart[i], e1 = c.adjStart[i + 1];
    std::int32_t e = e0;
    const int by = e < e1 ? computedBy(static_cast<std::size_t>(c.adjEntry[e] >> 1)) : self;
    if (by == self) continue;
    while (e < e1 && computedBy(static_cast<std::size_t>(c.adjEntry[e] >> 1)) == by) ++e;
    bool foreignLater = false;  // another foreign entry after the run: leave the particle to read them all
    for (std::int32_t q = e; q < e1; ++q)
      foreignLater |= computedBy(static_cast<std::size_t>(c.adjEntry[q] >> 1)) != self;
    if (foreignLater) continue;
    seeds[by].push_back(static_cast<std::int32_t>(i));
    b.kickBegin[i] = e;
  }
  b.seedEntryBegin.assign(2, 0);  // slot 0, the zero seed, sums nothing
  for (int t = 0; t < nt; ++t) {
    b.seedBegin[t] = b.seedParticle.size();
    for (const std::int32_t i : seeds[t]) {
      b.seedOf[i] = static_cast<std::int32_t>(b.seedParticle.size());
      b.seedParticle.push_back(i);
      b.seedEntry.insert(b.seedEntry.end(), c.adjEntry.begin() + c.adjStart[i], c.adjEntry.begin() + b.kickBegin[i]);
      b.seedEntryBegin.push_back(static_cast<std::int32_t>(b.seedEntry.size()));
    }
  }
  b.seedBegin[nt] = b.seedParticle.size();
  for (std::size_t i = 0; i < n; ++i)
    if (b.seedOf[i] != 0) b.seeded.push_back(static_cast<std::int32_t>(i));
  b.seeded.push_back(std::numeric_limits<std::int32_t>::max());
  return b;
}

}  // namespace fl
