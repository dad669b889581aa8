// Structure-of-arrays particle store. Hot per-step fields (position, velocity, force...) live in their
// own contiguous arrays; cold metadata (id, material, image counters) apart.
// Invariants: all arrays have size(); velocities are *fluctuating* velocities, i.e. relative to the
// cell's homogeneous velocity field L·x (see periodic_cell.hpp); positions are Cartesian and are wrapped
// into the cell only at neighbour-list rebuilds (between rebuilds they may leave the cell slightly).
#pragma once

#include <cstdint>
#include <vector>

#include "huge_pages.hpp"
#include "types.hpp"

namespace fl {

// What the contact passes read of one particle, in one 64-byte line (issue 6): the pass visits each partner
// through its index, and six separate arrays cost it up to six lines per partner. A copy of the store's
// values, written by the drift for every particle and refilled whole when positions are wrapped or masses
// change (Simulation::packPassParticles); the store stays the one owner of the state.
struct alignas(64) PassParticle {
  Vec3 x;          // position [m]
  double radius;   // r [m]
  Vec3 v;          // fluctuating velocity at the pass, i.e. after the drift's half kick [m/s]
  double invMass;  // 1/m [1/kg]
};
static_assert(sizeof(PassParticle) == 64, "one cache line per particle");

struct ParticleStore {
  // hot
  HugeVector<Vec3> pos;      // x [m]
  HugeVector<Vec3> vel;      // v', fluctuating velocity [m/s]
  HugeVector<Vec3> angVel;   // omega [rad/s]
  HugeVector<Vec3> force;    // total force of the last force pass [N]
  HugeVector<Vec3> torque;   // total torque [N m]
  HugeVector<double> radius;      // r [m]
  HugeVector<double> invMass;     // 1/m [1/kg] (density scaling applied)
  HugeVector<double> invInertia;  // 1/I, I = (2/5) m r^2 [1/(kg m^2)]
  // cold
  std::vector<std::int32_t> id;         // stable identity, survives re-ordering
  std::vector<std::uint16_t> material;  // index into the material list
  std::vector<Vec3i> image;             // times the particle was wrapped (unwrapped = x + H·image)

  std::size_t size() const { return pos.size(); }

  void add(const Vec3& x, double r, double density, int materialIndex) {
    const double m = density * 4.0 / 3.0 * kPi * r * r * r;
    id.push_back(static_cast<std::int32_t>(pos.size()));
    pos.push_back(x);
    vel.push_back(Vec3::Zero());
    angVel.push_back(Vec3::Zero());
    force.push_back(Vec3::Zero());
    torque.push_back(Vec3::Zero());
    radius.push_back(r);
    invMass.push_back(1.0 / m);
    invInertia.push_back(1.0 / (0.4 * m * r * r));
    material.push_back(static_cast<std::uint16_t>(materialIndex));
    image.push_back(Vec3i::Zero());
  }

  double mass(std::size_t i) const { return 1.0 / invMass[i]; }
  double maxRadius() const;
  double minRadius() const;
  double solidVolume() const;  // sum of 4/3 pi r^3 [m^3]
};

inline double ParticleStore::maxRadius() const {
  double m = 0.0;
  for (double r : radius) m = r > m ? r : m;
  return m;
}
inline double ParticleStore::minRadius() const {
  double m = radius.empty() ? 0.0 : radius[0];
  for (double r : radius) m = r < m ? r : m;
  return m;
}
inline double ParticleStore::solidVolume() const {
  double v = 0.0;
  for (double r : radius) v += 4.0 / 3.0 * kPi * r * r * r;
  return v;
}

}  // namespace fl
