// Deterministic parallelism (house style §12): the same scene gives the same bits with 1 or 2 threads.
#include <gtest/gtest.h>

#include <cstring>

#include "core/gas_generator.hpp"
#include "core/rng.hpp"
#include "core/simulation.hpp"
#include "test_support.hpp"

using namespace fl;

namespace {
Simulation compressed(int threads) {
  GasSpec g;
  g.count = 1500;
  g.solidFraction = 0.35;
  g.seed = 11;
  Packing pk = generateGas(g);
  Rng rng(3);
  for (auto& v : pk.particles.vel) v = Vec3(rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1));
  NumericsSettings num;
  num.threads = threads;
  num.restitution = 0.5;
  num.localDamping = 0.05;
  Simulation sim(std::move(pk.particles), pk.cell, {Material::paperGlass()}, num);
  Mat3 L = Mat3::Zero();
  L.diagonal() = Vec3(-400, -400, -500);
  sim.setVelocityGradient(L);
  return sim;
}

}  // namespace

TEST(Determinism, OneAndTwoThreadsGiveIdenticalBits) {
  Simulation a = compressed(1), b = compressed(2);
  a.run(4000);
  b.run(4000);
  ASSERT_GT(a.contacts().activeCount(), 1000u) << "the test must exercise many contacts";
  ASSERT_GT(a.profile().rebuilds, 2);
  EXPECT_TRUE(test::sameBits(a.particles().pos, b.particles().pos));
  EXPECT_TRUE(test::sameBits(a.particles().vel, b.particles().vel));
  EXPECT_TRUE(test::sameBits(a.particles().angVel, b.particles().angVel));
  EXPECT_TRUE(test::sameBits(a.contacts().history, b.contacts().history));
  EXPECT_EQ(std::memcmp(a.contactStress().data(), b.contactStress().data(), sizeof(Mat3)), 0);
  EXPECT_EQ(a.energy().frictionWork, b.energy().frictionWork);
}
