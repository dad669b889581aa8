// The contact store: the Verlet neighbour pairs, with each pair's contact history stored next to it
// and the results of the last force pass (so measurements read stored data, never re-run the law).
// A pair (i, j, image) couples particle i with the copy of j shifted by H·image, i < j.
// Stable key across rebuilds and wraps: (id_i, id_j, image - image_j + image_i) — see keyImage().
// Per-particle adjacency (CSR) lists each particle's pairs in pair order, so that forces are gathered in
// a fixed order: the same bits for any thread count.
#pragma once

#include <cstdint>
#include <vector>

#include "types.hpp"

namespace fl {

// Packed integer image vector, each component in [-128, 127].
struct Image {
  std::int8_t x = 0, y = 0, z = 0;
  bool isZero() const { return x == 0 && y == 0 && z == 0; }
  Vec3i vec() const { return {x, y, z}; }
  static Image of(const Vec3i& v) {
    return {static_cast<std::int8_t>(v.x()), static_cast<std::int8_t>(v.y()), static_cast<std::int8_t>(v.z())};
  }
};

// History a tangential model keeps per contact.
struct ContactHistory {
  Vec3 tangentialForce = Vec3::Zero();  // F_t acting on j [N], in the tangent plane
  double contactRadius = 0.0;           // a = sqrt(R* delta) of the previous step [m]
};

struct ContactStore {
  // pair definition (rebuilt with the neighbour list)
  std::vector<std::int32_t> first, second;  // particle indices i < j
  std::vector<Image> image;                  // shift applied to j
  // history (carried over across rebuilds by key)
  std::vector<ContactHistory> history;
  // results of the last force pass
  std::vector<Vec3> normal;     // unit n from i to j (valid when overlap > 0)
  std::vector<double> overlap;  // delta [m]; <= 0: not touching
  std::vector<double> distance; // |branch| [m], branch vector = distance * normal
  std::vector<double> normalForce;  // F_n on j along n, elastic + damping, >= 0 [N]
  std::vector<Vec3> force;      // total contact force on j [N] (on i it is -force)
  // adjacency: pairs of particle k are adjEntry[adjStart[k] .. adjStart[k+1]) as (pair << 1 | side),
  // side 0 when k is the pair's first particle, 1 when second.
  std::vector<std::int32_t> adjStart, adjEntry;

  std::size_t size() const { return first.size(); }
  bool active(std::size_t p) const { return overlap[p] > 0.0; }
  Vec3 branch(std::size_t p) const { return distance[p] * normal[p]; }
  std::size_t activeCount() const;
  void resizeResults();
  void buildAdjacency(std::size_t particleCount);
};

}  // namespace fl
