#include "neighbor_search.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <type_traits>
#include <utility>

#include "errors.hpp"
#include "thread_team.hpp"

namespace fl {

void checkCellSize(const PeriodicCell& cell, double cutoff) {
  const Vec3 w = cell.perpendicularWidths();
  if (w.minCoeff() <= 2.0 * cutoff) {
    std::ostringstream s;
    s << "periodic cell too small: its narrowest width " << w.minCoeff() << " m must exceed twice the "
      << "interaction range (2 r_max + skin = " << cutoff << " m). Use more particles, a smaller skin, "
      << "or stop the deformation earlier.";
    throw CellTooSmallError(s.str());
  }
}

namespace {

void sortPairs(PairList& L) {
  std::vector<std::size_t> order(L.first.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return L.first[a] != L.first[b] ? L.first[a] < L.first[b] : L.second[a] < L.second[b];
  });
  PairList out;
  out.first.reserve(order.size());
  out.second.reserve(order.size());
  out.image.reserve(order.size());
  for (auto k : order) {
    out.first.push_back(L.first[k]);
    out.second.push_back(L.second[k]);
    out.image.push_back(L.image[k]);
  }
  L = std::move(out);
}

}  // namespace

PairList findPairsBruteForce(const ParticleStore& p, const PeriodicCell& cell, double skin) {
  const double cutoff = 2.0 * p.maxRadius() + skin;
  checkCellSize(cell, cutoff);
  PairList L;
  const int n = static_cast<int>(p.size());
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      const double rc = p.radius[i] + p.radius[j] + skin;
      for (int a = -1; a <= 1; ++a)
        for (int b = -1; b <= 1; ++b)
          for (int c = -1; c <= 1; ++c) {
            const Vec3i img(a, b, c);
            const Vec3 d = p.pos[j] + cell.shift(img) - p.pos[i];
            if (d.squaredNorm() < rc * rc) {
              L.first.push_back(i);
              L.second.push_back(j);
              L.image.push_back(Image::of(img));
            }
          }
    }
  }
  return L;
}

std::size_t GridScratch::bytes() const {
  auto b = [](const auto& v) { return v.capacity() * sizeof(typename std::decay_t<decltype(v)>::value_type); };
  std::size_t total = b(binOf) + b(binStart) + b(binItem);
  for (const PairList& L : threadPairs) total += b(L.first) + b(L.second) + b(L.image);
  return total;
}

// A cell grid of bins no narrower than the cut-off, so that a particle's partners lie in its own bin and the 26
// around it. The particles are counted into their bins (index order inside a bin); each particle's pairs are then
// found in particle order, a row of three bins side by side read as one run, every candidate tested without a
// branch (the test, j > i and within the cut-off, advances the count of kept ones). The particles are split
// between the threads in contiguous ranges whose pairs are joined in range order: the list is the same for any
// thread count. A pair is tested with the same expression as the brute force's, on the same values. (A copy of
// the positions in bin order saved ~10 % of the search at 256 000 spheres, not worth its 32 bytes a particle.)
void findPairsGrid(const ParticleStore& p, const PeriodicCell& cell, double skin, int threads, ThreadTeam* team,
                   GridScratch& s, PairList& out) {
  const double cutoff = 2.0 * p.maxRadius() + skin;
  checkCellSize(cell, cutoff);
  const Vec3 w = cell.perpendicularWidths();
  Vec3i nb;
  for (int k = 0; k < 3; ++k) nb[k] = std::max(1, static_cast<int>(std::floor(w[k] / cutoff)));
  if (nb.minCoeff() < 3) throw Error("findPairsGrid: fewer than 3 bins per direction; use findPairs");
  const int n = static_cast<int>(p.size());
  const int nbins = nb.x() * nb.y() * nb.z();
  // bin of each particle from reduced coordinates (positions are wrapped: s in [0,1))
  s.binOf.resize(n);
  for (int i = 0; i < n; ++i) {
    const Vec3 r = cell.reduced(p.pos[i]);
    int b[3];
    for (int k = 0; k < 3; ++k) b[k] = std::clamp(static_cast<int>(std::floor(r[k] * nb[k])), 0, nb[k] - 1);
    s.binOf[i] = (b[2] * nb.y() + b[1]) * nb.x() + b[0];
  }
  // counting sort by bin, stable (index order inside a bin); binStart is the fill cursor, then shifted back
  s.binStart.assign(nbins + 1, 0);
  for (int i = 0; i < n; ++i) ++s.binStart[s.binOf[i] + 1];
  for (int b = 0; b < nbins; ++b) s.binStart[b + 1] += s.binStart[b];
  s.binItem.resize(n);
  for (int i = 0; i < n; ++i) s.binItem[s.binStart[s.binOf[i]]++] = i;
  for (int b = nbins; b > 0; --b) s.binStart[b] = s.binStart[b - 1];
  s.binStart[0] = 0;

  const int most = std::max({1, threads, team != nullptr ? team->held() : 0});
  if (static_cast<int>(s.threadPairs.size()) < most) s.threadPairs.resize(most);
  out.first.clear();
  out.second.clear();
  out.image.clear();
  int used = 1;  // the threads the loop ran on: OpenMP may give fewer than asked (a nested region gets one)
  const auto search = [&](int t, int nt) {
    if (t == 0) used = nt;
    PairList& dst = t == 0 ? out : s.threadPairs[t];
    if (t > 0) {
      dst.first.clear();
      dst.second.clear();
      dst.image.clear();
    }
    const int begin = static_cast<int>(static_cast<std::int64_t>(n) * t / nt);
    const int end = static_cast<int>(static_cast<std::int64_t>(n) * (t + 1) / nt);
    // a particle's candidates are tested without a branch: each is written to `hit` and kept by advancing the
    // count when it is a pair (a partner after i, within the cut-off); then sorted by j
    std::vector<std::pair<std::int32_t, Image>> hit(64);
    int hits = 0;
    int i = 0;
    Vec3 xi;
    double ri = 0.0;
    const auto scan = [&](int q0, int q1, const Vec3i& img) {
      if (hits + (q1 - q0) > static_cast<int>(hit.size())) hit.resize(2 * (hits + q1 - q0));
      const Vec3 shift = cell.shift(img);
      const Image packed = Image::of(img);
      for (int q = q0; q < q1; ++q) {
        const int j = s.binItem[q];
        const double rc = ri + p.radius[j] + skin;
        const Vec3 d = p.pos[j] + shift - xi;
        hit[hits] = {j, packed};
        hits += static_cast<int>((j > i) & (d.squaredNorm() < rc * rc));
      }
    };
    for (i = begin; i < end; ++i) {
      const int bi = s.binOf[i];
      const int bx = bi % nb.x(), by = (bi / nb.x()) % nb.y(), bz = bi / (nb.x() * nb.y());
      xi = p.pos[i];
      ri = p.radius[i];
      hits = 0;
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy) {
          int cz = bz + dz, cy = by + dy;
          Vec3i img = Vec3i::Zero();
          if (cz < 0) { cz += nb.z(); img.z() = -1; }
          else if (cz >= nb.z()) { cz -= nb.z(); img.z() = 1; }
          if (cy < 0) { cy += nb.y(); img.y() = -1; }
          else if (cy >= nb.y()) { cy -= nb.y(); img.y() = 1; }
          const int row = (cz * nb.y() + cy) * nb.x();
          if (bx >= 1 && bx + 1 < nb.x()) {  // the row's three bins side by side in memory, one image
            scan(s.binStart[row + bx - 1], s.binStart[row + bx + 2], img);
            continue;
          }
          for (int dx = -1; dx <= 1; ++dx) {
            int cx = bx + dx;
            img.x() = 0;
            if (cx < 0) { cx += nb.x(); img.x() = -1; }
            else if (cx >= nb.x()) { cx -= nb.x(); img.x() = 1; }
            scan(s.binStart[row + cx], s.binStart[row + cx + 1], img);
          }
        }
      for (int a = 1; a < hits; ++a)  // insertion sort: a handful of pairs
        for (int b = a; b > 0 && hit[b].first < hit[b - 1].first; --b) std::swap(hit[b], hit[b - 1]);
      for (int a = 0; a < hits; ++a) {
        dst.first.push_back(i);
        dst.second.push_back(hit[a].first);
        dst.image.push_back(hit[a].second);
      }
    }
  };
  ThreadTeam forked;  // not held: each() forks
  (team != nullptr ? *team : forked).each(threads, search);
  for (int t = 1; t < used; ++t) {  // not `most`: a thread that did not run left an earlier call's pairs there
    const PairList& part = s.threadPairs[t];
    out.first.insert(out.first.end(), part.first.begin(), part.first.end());
    out.second.insert(out.second.end(), part.second.begin(), part.second.end());
    out.image.insert(out.image.end(), part.image.begin(), part.image.end());
  }
}

PairList findPairsGrid(const ParticleStore& p, const PeriodicCell& cell, double skin, int threads,
                       ThreadTeam* team) {
  GridScratch scratch;
  PairList L;
  findPairsGrid(p, cell, skin, threads, team, scratch, L);
  return L;
}

void findPairs(const ParticleStore& p, const PeriodicCell& cell, double skin, int threads, ThreadTeam* team,
               GridScratch& scratch, PairList& out) {
  const double cutoff = 2.0 * p.maxRadius() + skin;
  const Vec3 w = cell.perpendicularWidths();
  if ((w / cutoff).minCoeff() >= 3.0) return findPairsGrid(p, cell, skin, threads, team, scratch, out);
  out = findPairsBruteForce(p, cell, skin);  // a cell too small for the grid: a few particles
  sortPairs(out);
}

PairList findPairs(const ParticleStore& p, const PeriodicCell& cell, double skin, int threads, ThreadTeam* team) {
  GridScratch scratch;
  PairList L;
  findPairs(p, cell, skin, threads, team, scratch, L);
  return L;
}

}  // namespace fl
