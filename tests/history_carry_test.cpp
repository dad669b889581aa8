// The contact history's carry-over across a rebuild, in place (core/history_carry.hpp), against the plain
// algorithm it replaces (a second array, filled from a list of the old pairs that carry a history), on random
// lists that grow, shrink and move their entries both ways, with particles that wrapped in between.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <tuple>
#include <utility>

#include "core/history_carry.hpp"

using namespace fl;

namespace {

struct List {
  HugeVector<std::int32_t> first, second;
  HugeVector<Image> image;
};

// A sorted list of distinct (i, j), i < j, drawn from the pairs of `particles` particles with probability `density`;
// images in [-1, 1].
List randomList(std::mt19937_64& rng, int particles, double density) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::uniform_int_distribution<int> img(-1, 1);
  List L;
  for (int i = 0; i < particles; ++i)
    for (int j = i + 1; j < particles; ++j)
      if (u(rng) < density) {
        L.first.push_back(i);
        L.second.push_back(j);
        L.image.push_back(Image::of(Vec3i(img(rng), img(rng), img(rng))));
      }
  return L;
}

ContactHistory historyOf(std::size_t k) {
  ContactHistory h;
  h.tangentialForce = Vec3(1.0 + k, -2.0 * k, 0.5);
  h.contactRadius = 1e-4 * (1 + k);
  return h;
}

// The algorithm before the in-place carry-over (simulation.cpp until the fortieth session).
template <class H>
HugeVector<H> referenceCarry(const List& old, const std::vector<Vec3i>& oldImages, const HugeVector<H>& oldValues,
                             const HugeVector<ContactHistory>& oldHistory, const List& now,
                             const std::vector<Vec3i>& newImages) {
  struct OldKey {
    std::int32_t i, j;
    Vec3i key;
    std::size_t index;
  };
  std::vector<OldKey> keys;
  for (std::size_t p = 0; p < old.first.size(); ++p) {
    if (oldHistory[p].tangentialForce.squaredNorm() == 0.0 && oldHistory[p].contactRadius == 0.0) continue;
    const int i = old.first[p], j = old.second[p];
    keys.push_back({i, j, old.image[p].vec() - oldImages[j] + oldImages[i], p});
  }
  HugeVector<H> out(now.first.size(), H{});
  std::size_t q = 0;
  for (std::size_t p = 0; p < now.first.size() && q < keys.size(); ++p) {
    const int i = now.first[p], j = now.second[p];
    while (q < keys.size() && (keys[q].i < i || (keys[q].i == i && keys[q].j < j))) ++q;
    for (std::size_t r = q; r < keys.size() && keys[r].i == i && keys[r].j == j; ++r)
      if (now.image[p].vec() - newImages[j] + newImages[i] == keys[r].key) {
        out[p] = oldValues[keys[r].index];
        break;
      }
  }
  return out;
}

}  // namespace

TEST(HistoryCarry, InPlaceEqualsTheTwoArrayCarryOnRandomLists) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::uniform_int_distribution<int> wrap(-1, 1);
  int moved = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const int particles = 40 + trial;
    // old and new lists of different densities: the new one longer, shorter or about the same
    const List old = randomList(rng, particles, 0.05 + 0.1 * u(rng));
    List now = randomList(rng, particles, 0.05 + 0.1 * u(rng));
    // most old pairs are in the new list too, with the same key
    std::vector<Vec3i> oldImages(particles, Vec3i::Zero()), newImages(particles);
    for (int k = 0; k < particles; ++k) {
      oldImages[k] = Vec3i(wrap(rng), wrap(rng), wrap(rng));
      newImages[k] = oldImages[k] + (u(rng) < 0.2 ? Vec3i(wrap(rng), wrap(rng), wrap(rng)) : Vec3i::Zero());
    }
    {
      std::set<std::pair<int, int>> inNew;
      for (std::size_t p = 0; p < now.first.size(); ++p) inNew.insert({now.first[p], now.second[p]});
      List merged;
      std::vector<std::tuple<int, int, Image>> all;
      for (std::size_t p = 0; p < now.first.size(); ++p) all.emplace_back(now.first[p], now.second[p], now.image[p]);
      for (std::size_t p = 0; p < old.first.size(); ++p) {
        const int i = old.first[p], j = old.second[p];
        if (inNew.count({i, j}) || u(rng) < 0.3) continue;
        // the same key after the particles' wraps: image - image_j + image_i unchanged
        const Vec3i img = old.image[p].vec() - oldImages[j] + oldImages[i] + newImages[j] - newImages[i];
        if (img.cwiseAbs().maxCoeff() > 100) continue;
        all.emplace_back(i, j, u(rng) < 0.9 ? Image::of(img) : Image::of(img + Vec3i(1, 0, 0)));  // 10 %: a new image
      }
      std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) {
        return std::get<0>(a) != std::get<0>(b) ? std::get<0>(a) < std::get<0>(b) : std::get<1>(a) < std::get<1>(b);
      });
      for (const auto& [i, j, img] : all) {
        merged.first.push_back(i);
        merged.second.push_back(j);
        merged.image.push_back(img);
      }
      now = std::move(merged);
    }
    HugeVector<ContactHistory> history(old.first.size());
    HugeVector<MdHistory> md(old.first.size());
    for (std::size_t k = 0; k < history.size(); ++k) {
      if (u(rng) < 0.8) history[k] = historyOf(k);  // 20 %: no history, nothing to carry
      md[k].prevNormalForce = 3.0 * k + 1.0;
      md[k].branch = MdBranch::Unloading;
    }
    const auto expected = referenceCarry(old, oldImages, history, history, now, newImages);
    const auto expectedMd = referenceCarry(old, oldImages, md, history, now, newImages);

    HugeVector<std::uint32_t> match;
    matchHistory({old.first, old.second, old.image, oldImages}, history, {now.first, now.second, now.image, newImages},
                 match);
    for (std::size_t p = 0; p < match.size(); ++p) moved += match[p] != 0 && match[p] - 1 != p;
    moveHistory(history, match);
    moveHistory(md, match);
    ASSERT_EQ(history.size(), now.first.size());
    ASSERT_EQ(md.size(), now.first.size());
    for (std::size_t p = 0; p < history.size(); ++p) {
      ASSERT_EQ(history[p].tangentialForce, expected[p].tangentialForce) << "trial " << trial << " pair " << p;
      ASSERT_EQ(history[p].contactRadius, expected[p].contactRadius) << "trial " << trial << " pair " << p;
      ASSERT_EQ(md[p].prevNormalForce, expectedMd[p].prevNormalForce) << "trial " << trial << " pair " << p;
      ASSERT_EQ(md[p].branch, expectedMd[p].branch) << "trial " << trial << " pair " << p;
    }
  }
  EXPECT_GT(moved, 1000) << "the trials moved entries";
}

// Entries that move down and up in one list, by hand: old pairs (0,1) (0,2) (1,2) (2,3) (3,4); the new list drops
// (0,1) and adds (1,3) and (2,4): (0,2) and (1,2) move down one slot, (2,3) stays, (3,4) moves up one.
TEST(HistoryCarry, EntriesMoveDownAndUpInOneArray) {
  HugeVector<std::int32_t> of{0, 0, 1, 2, 3}, os{1, 2, 2, 3, 4}, nf{0, 1, 1, 2, 2, 3}, ns{2, 2, 3, 3, 4, 4};
  HugeVector<Image> oi(5), ni(6);
  const std::vector<Vec3i> images(5, Vec3i::Zero());
  HugeVector<ContactHistory> h(5);
  for (std::size_t k = 0; k < 5; ++k) h[k] = historyOf(k);
  HugeVector<std::uint32_t> match;
  matchHistory({of, os, oi, images}, h, {nf, ns, ni, images}, match);
  EXPECT_EQ(match, (HugeVector<std::uint32_t>{2, 3, 0, 4, 0, 5}));
  moveHistory(h, match);
  ASSERT_EQ(h.size(), 6u);
  const double expected[6] = {historyOf(1).contactRadius, historyOf(2).contactRadius, 0.0,
                              historyOf(3).contactRadius, 0.0, historyOf(4).contactRadius};
  for (std::size_t p = 0; p < 6; ++p) EXPECT_EQ(h[p].contactRadius, expected[p]) << "pair " << p;
  EXPECT_EQ(h[5].tangentialForce, historyOf(4).tangentialForce);
  EXPECT_EQ(h[2].tangentialForce, Vec3::Zero());
}
