// The validation build's invariant checks hold on a real compressed packing and catch corruption.
#include <gtest/gtest.h>

#include "core/binary_io.hpp"
#include "core/errors.hpp"
#include "core/gas_generator.hpp"
#include "core/invariants.hpp"

using namespace fl;

namespace {
// A frictional gas of glass beads under isotropic compression (strain rate 300/s), restitution 0.5.
Simulation compressingGas(int count, double solidFraction) {
  GasSpec g;
  g.count = count;
  g.solidFraction = solidFraction;
  Packing pk = generateGas(g);
  NumericsSettings num;
  num.restitution = 0.5;
  Simulation sim(std::move(pk.particles), pk.cell, {Material::paperGlass()}, num);
  Mat3 L = Mat3::Zero();
  L.diagonal().setConstant(-300);
  sim.setVelocityGradient(L);
  return sim;
}
}  // namespace

TEST(Invariants, HoldOnACompressedFrictionalPackingAndCatchCorruption) {
  Simulation sim = compressingGas(500, 0.35);
  for (int k = 0; k < 60; ++k) {
    sim.run(100);
    EXPECT_NO_THROW(checkInvariants(sim));
  }
  ASSERT_GT(sim.contacts().activeCount(), 100u);
  ASSERT_TRUE(sim.contacts().touchedValid) << "the default law's pass keeps its words of touching pairs";
  Simulation broken = std::move(sim);
  broken.mutableParticles().vel[7].x() = std::nan("");
  EXPECT_THROW(checkInvariants(broken), Error);
}

// The contact pass reads a copy of x, r, v and 1/m (PassParticle). It must follow the store through every
// path that changes them: drift, rebuild (wrapping), restore, reconfigure (new masses) and refresh after an
// edit; an edit without refresh() leaves it stale, and the check says so.
TEST(Invariants, ContactPassCopyFollowsRestoreReconfigureAndEdits) {
  Simulation sim = compressingGas(300, 0.4);
  sim.run(2000);
  ASSERT_GT(sim.profile().rebuilds, 0);
  EXPECT_NO_THROW(checkInvariants(sim));
  BinaryWriter w;
  sim.saveState(w);
  BinaryReader r(w.bytes(), "state");
  Simulation b = Simulation::restoreState(r);
  EXPECT_NO_THROW(checkInvariants(b));
  Material heavier = Material::paperGlass();
  heavier.density *= 3.0;
  b.reconfigure(heavier, b.numerics());
  EXPECT_NO_THROW(checkInvariants(b));
  b.run(50);
  EXPECT_NO_THROW(checkInvariants(b));
  b.mutableParticles().radius[3] *= 1.01;
  EXPECT_THROW(checkInvariants(b), Error);
  b.refresh();
  EXPECT_NO_THROW(checkInvariants(b));
}
