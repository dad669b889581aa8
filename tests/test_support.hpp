// Small builders shared by the core tests.
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "core/gas_generator.hpp"
#include "core/rng.hpp"
#include "core/simulation.hpp"

namespace fl::test {

// A random gas of paper glass beads (generateGas) with each velocity component uniform in ±0.1 m/s: the
// start of the many-contact runs (determinism, restart, diagnostics, Mindlin–Deresiewicz).
inline Packing stirredGas(int count, double solidFraction, std::uint64_t gasSeed, std::uint64_t velocitySeed) {
  GasSpec g;
  g.count = count;
  g.solidFraction = solidFraction;
  g.seed = gasSeed;
  Packing pk = generateGas(g);
  Rng rng(velocitySeed);
  for (auto& v : pk.particles.vel) v = Vec3(rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1));
  return pk;
}

// Two spheres in a large periodic box (so they meet only each other), moving at v1, v2.
inline Simulation twoSpheres(double r1, double r2, const Vec3& x1, const Vec3& x2, const Vec3& v1,
                             const Vec3& v2, const Material& m, NumericsSettings num, double box = 1.0) {
  ParticleStore p;
  p.add(x1, r1, m.density, 0);
  p.add(x2, r2, m.density, 0);
  p.vel[0] = v1;
  p.vel[1] = v2;
  return Simulation(std::move(p), PeriodicCell::box(box, box, box), {m}, num);
}

inline double effYoung(const Material& a, const Material& b) {
  return 1.0 / ((1 - a.poissonRatio * a.poissonRatio) / a.youngModulus +
                (1 - b.poissonRatio * b.poissonRatio) / b.youngModulus);
}

inline Vec3 momentum(const ParticleStore& p) {
  Vec3 s = Vec3::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) s += p.vel[i] / p.invMass[i];
  return s;
}

// True when both arrays hold the same bits (determinism and restart tests compare states bit for bit).
template <class T, class A>
bool sameBits(const std::vector<T, A>& a, const std::vector<T, A>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

// `count` beads of the stirred gas (solid fraction 0.35) under a compressing velocity gradient, with the given
// numerics: thousands of contacts, sliding and neighbour rebuilds within a few thousand steps.
inline Simulation compressingGasWith(int count, const NumericsSettings& num) {
  Packing pk = stirredGas(count, 0.35, 11, 3);
  Simulation sim(std::move(pk.particles), pk.cell, {Material::paperGlass()}, num);
  Mat3 L = Mat3::Zero();
  L.diagonal() = Vec3(-400, -400, -500);
  sim.setVelocityGradient(L);
  return sim;
}

// The 1500-bead compressing gas with the default contact laws (the determinism and large-state tests).
inline Simulation compressingGas(int threads, double localDamping = 0.05, double restitution = 0.5,
                                 bool trackEnergy = true) {
  NumericsSettings num;
  num.threads = threads;
  num.restitution = restitution;
  num.trackEnergy = trackEnergy;
  num.localDamping = localDamping;
  return compressingGasWith(1500, num);
}

// Expects a and b to hold the same bits: the particles' state, forces and torques, the contact history and
// results, and the stress.
inline void expectSameBits(const Simulation& a, const Simulation& b) {
  EXPECT_TRUE(sameBits(a.particles().pos, b.particles().pos));
  EXPECT_TRUE(sameBits(a.particles().vel, b.particles().vel));
  EXPECT_TRUE(sameBits(a.particles().angVel, b.particles().angVel));
  EXPECT_TRUE(sameBits(a.particles().force, b.particles().force));
  EXPECT_TRUE(sameBits(a.particles().torque, b.particles().torque));
  EXPECT_TRUE(sameBits(a.contacts().history, b.contacts().history));
  EXPECT_TRUE(sameBits(a.contacts().result, b.contacts().result));
  EXPECT_EQ(std::memcmp(a.contactStress().data(), b.contactStress().data(), sizeof(Mat3)), 0);
}

// Expects the energy ledgers of a and b to hold the same bits, term by term.
inline void expectSameEnergy(Simulation& a, Simulation& b) {
  const EnergyLedger& ea = a.energy();
  const EnergyLedger& eb = b.energy();
  EXPECT_EQ(ea.localDampingWork, eb.localDampingWork);
  EXPECT_EQ(ea.contactDampingWork, eb.contactDampingWork);
  EXPECT_EQ(ea.frictionWork, eb.frictionWork);
  EXPECT_EQ(ea.boundaryWork, eb.boundaryWork);
  EXPECT_EQ(ea.kinetic, eb.kinetic);
}

}  // namespace fl::test
