// Contact detection: the cell grid finds exactly the brute-force pairs on random packings, in
// orthorhombic and sheared cells; too small a cell is a clear error.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <tuple>

#include "core/errors.hpp"
#include "core/gas_generator.hpp"
#include "core/neighbor_search.hpp"

using namespace fl;

namespace {
std::set<std::tuple<int, int, int, int, int>> asSet(const PairList& L) {
  std::set<std::tuple<int, int, int, int, int>> s;
  for (std::size_t k = 0; k < L.first.size(); ++k)
    s.insert({L.first[k], L.second[k], L.image[k].x, L.image[k].y, L.image[k].z});
  EXPECT_EQ(s.size(), L.first.size()) << "duplicate pairs";
  return s;
}
}  // namespace

TEST(NeighbourSearch, GridEqualsBruteForceOnRandomPackings) {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    GasSpec g;
    g.count = 600;
    g.solidFraction = 0.3;
    g.seed = seed;
    Packing pk = generateGas(g);
    const double skin = 0.2e-3;
    const PairList grid = findPairsGrid(pk.particles, pk.cell, skin, 2);
    const PairList brute = findPairsBruteForce(pk.particles, pk.cell, skin);
    EXPECT_GT(grid.first.size(), 500u);
    EXPECT_EQ(asSet(grid), asSet(brute)) << "seed " << seed;
    // output is sorted by (i, j), as the history transfer requires
    for (std::size_t k = 1; k < grid.first.size(); ++k)
      EXPECT_TRUE(grid.first[k - 1] < grid.first[k] ||
                  (grid.first[k - 1] == grid.first[k] && grid.second[k - 1] <= grid.second[k]));
  }
}

TEST(NeighbourSearch, GridEqualsBruteForceInAShearedCell) {
  GasSpec g;
  g.count = 600;
  g.solidFraction = 0.3;
  Packing pk = generateGas(g);
  // shear the cell and the particles affinely by 10 %
  Mat3 F = Mat3::Identity();
  F(0, 2) = 0.1;
  pk.cell.setMatrix(F * pk.cell.matrix());
  for (auto& x : pk.particles.pos) {
    x = F * x;
    pk.cell.wrap(x);
  }
  const double skin = 0.2e-3;
  EXPECT_EQ(asSet(findPairsGrid(pk.particles, pk.cell, skin, 1)), asSet(findPairsBruteForce(pk.particles, pk.cell, skin)));
}

TEST(NeighbourSearch, TooSmallACellIsAClearError) {
  ParticleStore p;
  p.add(Vec3(0.5e-3, 0.5e-3, 0.5e-3), 1e-3, 2500, 0);
  p.add(Vec3(2e-3, 2e-3, 2e-3), 1e-3, 2500, 0);
  const PeriodicCell cell = PeriodicCell::box(3e-3, 3e-3, 3e-3);
  try {
    findPairs(p, cell, 1e-4, 1);
    FAIL() << "expected CellTooSmallError";
  } catch (const CellTooSmallError& e) {
    EXPECT_NE(std::string(e.what()).find("too small"), std::string::npos);
  }
}

// The grid's list is the brute force's sorted by (i, j), entry for entry, on any thread count; the form that
// reuses its output and scratch gives the same list on a second packing (a shorter and then a longer list).
TEST(NeighbourSearch, GridListIsTheSortedBruteForceOnAnyThreadCountWithReusedArrays) {
  GridScratch scratch;
  PairList reused;
  for (double fraction : {0.3, 0.15, 0.35}) {
    GasSpec g;
    g.count = 700;
    g.solidFraction = fraction;
    g.seed = 11;
    Packing pk = generateGas(g);
    const double skin = 0.15e-3;
    PairList brute = findPairsBruteForce(pk.particles, pk.cell, skin);
    std::vector<std::tuple<int, int, int, int, int>> sorted;
    for (std::size_t k = 0; k < brute.first.size(); ++k)
      sorted.emplace_back(brute.first[k], brute.second[k], brute.image[k].x, brute.image[k].y, brute.image[k].z);
    std::sort(sorted.begin(), sorted.end());
    const auto entries = [](const PairList& L) {
      std::vector<std::tuple<int, int, int, int, int>> e;
      for (std::size_t k = 0; k < L.first.size(); ++k)
        e.emplace_back(L.first[k], L.second[k], L.image[k].x, L.image[k].y, L.image[k].z);
      return e;
    };
    for (int threads : {1, 2, 3}) {
      EXPECT_EQ(entries(findPairsGrid(pk.particles, pk.cell, skin, threads)), sorted)
          << "solid fraction " << fraction << ", " << threads << " threads";
      findPairs(pk.particles, pk.cell, skin, threads, nullptr, scratch, reused);
      EXPECT_EQ(entries(reused), sorted) << "reused arrays, solid fraction " << fraction << ", " << threads << " threads";
    }
  }
}

// When OpenMP runs the search on fewer threads than asked (here a region nested in another gets one), only the
// threads that ran give pairs: the scratch of an earlier 2-thread call must not be joined again.
TEST(NeighbourSearch, FewerThreadsThanAskedJoinOnlyTheThreadsThatRan) {
  GasSpec g;
  g.count = 700;
  g.solidFraction = 0.3;
  Packing pk = generateGas(g);
  const double skin = 0.15e-3;
  const PairList expected = findPairsGrid(pk.particles, pk.cell, skin, 1);
  GridScratch scratch;
  PairList out;
  findPairs(pk.particles, pk.cell, skin, 2, nullptr, scratch, out);  // fills the second thread's scratch
  ASSERT_EQ(out.first.size(), expected.first.size());
#pragma omp parallel num_threads(2)
  {
#pragma omp single
    findPairs(pk.particles, pk.cell, skin, 2, nullptr, scratch, out);  // nested: one thread
  }
  EXPECT_EQ(out.first, expected.first);
  EXPECT_EQ(out.second, expected.second);
}
