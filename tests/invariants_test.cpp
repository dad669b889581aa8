// The validation build's invariant checks hold on a real compressed packing and catch corruption.
#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "core/gas_generator.hpp"
#include "core/invariants.hpp"

using namespace fl;

TEST(Invariants, HoldOnACompressedFrictionalPackingAndCatchCorruption) {
  GasSpec g;
  g.count = 500;
  g.solidFraction = 0.35;
  Packing pk = generateGas(g);
  NumericsSettings num;
  num.restitution = 0.5;
  Simulation sim(std::move(pk.particles), pk.cell, {Material::paperGlass()}, num);
  Mat3 L = Mat3::Zero();
  L.diagonal().setConstant(-300);
  sim.setVelocityGradient(L);
  for (int k = 0; k < 60; ++k) {
    sim.run(100);
    EXPECT_NO_THROW(checkInvariants(sim));
  }
  ASSERT_GT(sim.contacts().activeCount(), 100u);
  Simulation broken = std::move(sim);
  broken.mutableParticles().vel[7].x() = std::nan("");
  EXPECT_THROW(checkInvariants(broken), Error);
}
