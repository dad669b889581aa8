#include "neighbor_search.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

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

PairList findPairsGrid(const ParticleStore& p, const PeriodicCell& cell, double skin, int threads,
                       ThreadTeam* team) {
  const double cutoff = 2.0 * p.maxRadius() + skin;
  checkCellSize(cell, cutoff);
  const Vec3 w = cell.perpendicularWidths();
  Vec3i nb;
  for (int k = 0; k < 3; ++k) nb[k] = std::max(1, static_cast<int>(std::floor(w[k] / cutoff)));
  if (nb.minCoeff() < 3) throw Error("findPairsGrid: fewer than 3 bins per direction; use findPairs");
  const int n = static_cast<int>(p.size());
  const int nbins = nb.x() * nb.y() * nb.z();
  // bin of each particle from reduced coordinates (positions are wrapped: s in [0,1))
  std::vector<std::int32_t> binOf(n);
  for (int i = 0; i < n; ++i) {
    const Vec3 s = cell.reduced(p.pos[i]);
    int b[3];
    for (int k = 0; k < 3; ++k) b[k] = std::clamp(static_cast<int>(std::floor(s[k] * nb[k])), 0, nb[k] - 1);
    binOf[i] = (b[2] * nb.y() + b[1]) * nb.x() + b[0];
  }
  // counting sort of particle indices by bin (stable: index order inside a bin)
  std::vector<std::int32_t> binStart(nbins + 1, 0), binItems(n);
  for (int i = 0; i < n; ++i) ++binStart[binOf[i] + 1];
  for (int b = 0; b < nbins; ++b) binStart[b + 1] += binStart[b];
  {
    std::vector<std::int32_t> fill(binStart.begin(), binStart.end() - 1);
    for (int i = 0; i < n; ++i) binItems[fill[binOf[i]]++] = i;
  }
  // per-particle candidate lists, built in parallel, concatenated in particle order (deterministic)
  std::vector<std::vector<std::pair<std::int32_t, Image>>> found(n);
  const auto search = [&](int, int) {
#pragma omp for schedule(dynamic, 64)
  for (int i = 0; i < n; ++i) {
    const int bi = binOf[i];
    const int bx = bi % nb.x(), by = (bi / nb.x()) % nb.y(), bz = bi / (nb.x() * nb.y());
    auto& out = found[i];
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          int c[3] = {bx + dx, by + dy, bz + dz};
          Vec3i img = Vec3i::Zero();
          for (int k = 0; k < 3; ++k) {
            if (c[k] < 0) { c[k] += nb[k]; img[k] = -1; }
            else if (c[k] >= nb[k]) { c[k] -= nb[k]; img[k] = 1; }
          }
          const int b = (c[2] * nb.y() + c[1]) * nb.x() + c[0];
          const Vec3 shift = cell.shift(img);
          for (int q = binStart[b]; q < binStart[b + 1]; ++q) {
            const int j = binItems[q];
            if (j <= i) continue;
            const double rc = p.radius[i] + p.radius[j] + skin;
            const Vec3 d = p.pos[j] + shift - p.pos[i];
            if (d.squaredNorm() < rc * rc) out.push_back({j, Image::of(img)});
          }
        }
    std::sort(out.begin(), out.end(), [](auto& a, auto& b) { return a.first < b.first; });
  }
  };
  ThreadTeam forked;  // not held: each() forks
  (team != nullptr ? *team : forked).each(threads, search);
  PairList L;
  std::size_t total = 0;
  for (auto& f : found) total += f.size();
  L.first.reserve(total);
  L.second.reserve(total);
  L.image.reserve(total);
  for (int i = 0; i < n; ++i)
    for (auto& [j, img] : found[i]) {
      L.first.push_back(i);
      L.second.push_back(j);
      L.image.push_back(img);
    }
  return L;
}

PairList findPairs(const ParticleStore& p, const PeriodicCell& cell, double skin, int threads, ThreadTeam* team) {
  const double cutoff = 2.0 * p.maxRadius() + skin;
  const Vec3 w = cell.perpendicularWidths();
  if ((w / cutoff).minCoeff() >= 3.0) return findPairsGrid(p, cell, skin, threads, team);
  PairList L = findPairsBruteForce(p, cell, skin);
  sortPairs(L);
  return L;
}

}  // namespace fl
