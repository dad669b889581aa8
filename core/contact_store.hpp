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

// Branch of the Mindlin–Deresiewicz (1953) tangential law, with Thornton's (1991) names.
enum class MdBranch : std::int32_t { Loading = 0, Unloading = 1, Reloading = 2 };

// Extra history of the Mindlin–Deresiewicz tangential law (core/mindlin_deresiewicz.hpp), kept in its own
// array (ContactStore::mdHistory) that exists only when that law is selected, so the default law's
// per-pair data and loop are unchanged. Vectors live in the tangent plane and are rotated with F_t.
struct MdHistory {
  Vec3 turnLoad = Vec3::Zero();    // T*: F_t where the last loading/reloading branch reversed [N]
  Vec3 turnUnload = Vec3::Zero();  // T**: F_t where the last unloading branch reversed [N]
  Vec3 direction = Vec3::Zero();   // unit direction of the last tangential displacement increment [-]
  double prevNormalForce = 0.0;    // N of the previous step [N]
  double locked = 0.0;             // micro-slip energy locked in the contact (ledger: stored) [J], >= 0
  MdBranch branch = MdBranch::Loading;
  std::int32_t pad = 0;            // explicit, so checkpoints hold no indeterminate bytes
};

// What the kick gathers of one pair, in one 64-byte line (issue 6): the force on j, the moment n x f and
// delta/2, so a particle's torque -(r - delta/2) n x f needs no other pair array. Zero when not touching.
struct alignas(64) KickTerms {
  Vec3 force = Vec3::Zero();   // f on j [N] (on i: -f)
  Vec3 moment = Vec3::Zero();  // n x f [N]
  double halfOverlap = 0.0;    // delta / 2 [m]
};

struct ContactStore {
  // pair definition (rebuilt with the neighbour list)
  std::vector<std::int32_t> first, second;  // particle indices i < j
  std::vector<Image> image;                  // shift applied to j
  // history (carried over across rebuilds by key)
  std::vector<ContactHistory> history;
  std::vector<MdHistory> mdHistory;  // same length as history with the Mindlin–Deresiewicz law, else empty
  // results of the last force pass
  std::vector<Vec3> normal;     // unit n from i to j (valid when overlap > 0)
  std::vector<double> overlap;  // delta [m]; <= 0: not touching
  std::vector<double> distance; // |branch| [m], branch vector = distance * normal
  std::vector<double> normalForce;  // F_n on j along n, elastic + damping, >= 0 [N]
  std::vector<Vec3> force;      // total contact force on j [N] (on i it is -force)
  std::vector<KickTerms> kick;  // the kick's copy of force, n x force and delta/2 (derived, not saved)
  // adjacency: pairs of particle k are adjEntry[adjStart[k] .. adjStart[k+1]) as (pair << 1 | side),
  // side 0 when k is the pair's first particle, 1 when second.
  std::vector<std::int32_t> adjStart, adjEntry;

  std::size_t size() const { return first.size(); }
  bool active(std::size_t p) const { return overlap[p] > 0.0; }
  Vec3 branch(std::size_t p) const { return distance[p] * normal[p]; }
  std::size_t activeCount() const;
  void resizeResults();
  void deriveKickTerms();  // kick from force, normal and overlap (after a checkpoint is read)
  void buildAdjacency(std::size_t particleCount);
};

}  // namespace fl
