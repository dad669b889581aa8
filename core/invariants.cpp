#include "invariants.hpp"

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "errors.hpp"

namespace fl {

namespace {
[[noreturn]] void violated(const std::string& what) { throw Error("invariant violated: " + what); }
}  // namespace

void checkInvariants(const Simulation& sim) {
  const ParticleStore& p = sim.particles();
  const ContactStore& c = sim.contacts();
  const std::size_t n = p.size();
  for (std::size_t i = 0; i < n; ++i)
    if (!p.pos[i].allFinite() || !p.vel[i].allFinite() || !p.angVel[i].allFinite() || !p.force[i].allFinite())
      violated("particle " + std::to_string(i) + " has a non-finite position, velocity or force");
  if (!(sim.cell().volume() > 0.0)) violated("cell volume <= 0");
  // the contact pass reads its own copy of the particles: it must hold the store's bits (but for the
  // velocity, which the kick has moved on by half a step since the pass read it)
  const HugeVector<PassParticle>& pass = sim.passParticles();
  if (pass.size() != n) violated("the contact pass's particle copy has the wrong length");
  for (std::size_t i = 0; i < n; ++i) {
    const PassParticle& q = pass[i];
    if (std::memcmp(q.x.data(), p.pos[i].data(), sizeof(Vec3)) != 0 ||
        std::memcmp(&q.radius, &p.radius[i], sizeof(double)) != 0 ||
        std::memcmp(&q.invMass, &p.invMass[i], sizeof(double)) != 0)
      violated("the contact pass's copy of particle " + std::to_string(i) + " differs from the store");
  }
  std::vector<int> seen(n, 0);
  for (std::size_t k = 0; k < c.size(); ++k) {
    const int i = c.first[k], j = c.second[k];
    if (i < 0 || j <= i || static_cast<std::size_t>(j) >= n) violated("pair " + std::to_string(k) + " indices");
    ++seen[i];
    ++seen[j];
    if (!c.active(k)) continue;
    const PairResult& q = c.result[k];
    // the stored overlap agrees with the positions: l = x_j + H image - x_i, |l| = R - delta; the moment is
    // n x f with n = l / |l|
    const double R = p.radius[i] + p.radius[j];
    const Vec3 l = c.branch(k, p, sim.cell());
    if (std::abs(l.norm() + q.overlap - R) > 1e-12 * R) violated("pair " + std::to_string(k) + " overlap");
    const Vec3 normal = l.normalized();
    if ((q.moment - normal.cross(q.force)).norm() > 1e-9 * q.force.norm() + 1e-300)
      violated("pair " + std::to_string(k) + " moment");
    const Vec3& ft = c.history[k].tangentialForce;
    // round-off of the projection scales with the contact's forces, not with |F_t| (which may be ~0)
    if (std::abs(ft.dot(normal)) > 1e-9 * ft.norm() + 1e-12 * q.normalForce + 1e-300)
      violated("pair " + std::to_string(k) + " tangential force out of the tangent plane");
    const double mu = sim.materials()[p.material[i]].friction;
    if (ft.norm() > mu * q.normalForce * (1 + 1e-9) + 1e-300)
      violated("pair " + std::to_string(k) + " tangential force above the Coulomb limit");
  }
  // the default law's words of touching pairs mirror the history (a > 0) while they are marked valid
  if (c.touchedValid) {
    if (c.touched.size() != (c.size() + 63) / 64) violated("words of touching pairs: wrong length");
    for (std::size_t k = 0; k < c.size(); ++k)
      if (((c.touched[k / 64] >> (k % 64)) & 1) != (c.history[k].contactRadius != 0.0 ? 1u : 0u))
        violated("pair " + std::to_string(k) + " touching bit differs from its history");
  }
  if (c.adjStart.size() != n + 1 || c.adjEntry.size() != 2 * c.size()) violated("adjacency sizes");
  for (std::size_t i = 0; i < n; ++i) {
    if (c.adjStart[i + 1] - c.adjStart[i] != seen[i]) violated("adjacency of particle " + std::to_string(i));
    for (int e = c.adjStart[i]; e < c.adjStart[i + 1]; ++e) {
      const int entry = c.adjEntry[e], pair = entry >> 1;
      const int self = (entry & 1) ? c.second[pair] : c.first[pair];
      if (self != static_cast<int>(i)) violated("adjacency entry of particle " + std::to_string(i));
    }
  }
}

}  // namespace fl
