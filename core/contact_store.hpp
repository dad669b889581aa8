// The contact store: the Verlet neighbour pairs, with each pair's contact history stored next to it
// and the results of the last force pass (so measurements read stored data, never re-run the law).
// A pair (i, j, image) couples particle i with the copy of j shifted by H·image, i < j.
// Stable key across rebuilds and wraps: (id_i, id_j, image - image_j + image_i) — see keyImage().
// Per-particle adjacency (CSR) lists each particle's pairs in pair order, so that forces are gathered in
// a fixed order: the same bits for any thread count.
#pragma once

#include <cstdint>
#include <vector>

#include "huge_pages.hpp"
#include "particle_store.hpp"
#include "periodic_cell.hpp"
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

// The results of the last force pass for one pair, in one 64-byte line (issue 6): what the kick gathers
// (force; moment and overlap for the torques) and what the measurements read. Zero when not touching.
// The normal is not stored: it is the branch vector's direction, and between steps the positions are those
// the pass used (ContactStore::branch, normal). The moment n x f, computed with the law (vectorised), spares
// the kick a cross product per pair and side.
struct alignas(64) PairResult {
  Vec3 force = Vec3::Zero();   // total contact force on j [N] (on i it is -force)
  Vec3 moment = Vec3::Zero();  // n x force [N], n the unit normal from i to j; the torque on either particle
                               // is -(r - delta/2) n x f (contact point on the pair axis)
  double overlap = 0.0;        // delta [m]; <= 0: not touching
  double normalForce = 0.0;    // F_n on j along n, elastic + damping, >= 0 [N]
};
// one line, eight doubles in this order: the contact pass may write it whole (streamLine, streaming_store.hpp)
static_assert(sizeof(PairResult) == 64 && alignof(PairResult) == 64, "one aligned cache line per pair");

struct ContactStore {
  // pair definition (rebuilt with the neighbour list)
  HugeVector<std::int32_t> first, second;  // particle indices i < j
  HugeVector<Image> image;                  // shift applied to j
  // history (carried over across rebuilds by key)
  HugeVector<ContactHistory> history;
  HugeVector<MdHistory> mdHistory;  // same length as history with the Mindlin–Deresiewicz law, else empty
  // results of the last force pass, one line per pair
  HugeVector<PairResult> result;
  // bit p % 64 of word p / 64 is set when pair p holds a contact, i.e. its history has a > 0: the default law's
  // pass finds the contacts that opened from these words instead of reading every listed pair's history.
  // Mirrors the history while touchedValid (markTouched sets both; the other law's pass clears the flag; a new
  // or restored store starts without).
  HugeVector<std::uint64_t> touched;
  bool touchedValid = false;
  // adjacency: pairs of particle k are adjEntry[adjStart[k] .. adjStart[k+1]) as (pair << 1 | side),
  // side 0 when k is the pair's first particle, 1 when second.
  HugeVector<std::int32_t> adjStart, adjEntry;

  std::size_t size() const { return first.size(); }
  bool active(std::size_t p) const { return result[p].overlap > 0.0; }
  // |l| = r_i + r_j - delta, for a touching pair
  double distance(std::size_t p, const HugeVector<double>& radius) const {
    return radius[first[p]] + radius[second[p]] - result[p].overlap;
  }
  // the branch vector l = x_j + H image - x_i from i to j's image, and the contact normal n = l / |l|, from the
  // particles' positions: between steps those of the last force pass, so its geometry
  Vec3 branch(std::size_t p, const ParticleStore& particles, const PeriodicCell& cell) const {
    return particles.pos[second[p]] - particles.pos[first[p]] + cell.shift(image[p].vec());
  }
  Vec3 normal(std::size_t p, const ParticleStore& particles, const PeriodicCell& cell) const {
    return branch(p, particles, cell).normalized();
  }
  std::size_t activeCount() const;
  void resizeResults();
  void markTouched();  // `touched` from the history
  void buildAdjacency(std::size_t particleCount);
};

}  // namespace fl
