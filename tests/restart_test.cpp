// Restart (verification ladder §5): save at step N, reload, run k steps: positions, velocities and
// contact history equal an unbroken run bit for bit.
#include <gtest/gtest.h>

#include <cstring>

#include "core/binary_io.hpp"
#include "core/simulation.hpp"
#include "test_support.hpp"

using namespace fl;

TEST(Restart, SaveReloadRunIsBitIdenticalToAnUnbrokenRun) {
  Packing pk = test::stirredGas(800, 0.35, 1, 5);
  NumericsSettings num;
  num.restitution = 0.6;
  num.localDamping = 0.05;
  num.threads = 1;
  Simulation a(std::move(pk.particles), pk.cell, {Material::paperGlass()}, num);
  Mat3 L = Mat3::Zero();
  L.diagonal() = Vec3(-300, -300, -400);
  a.setVelocityGradient(L);
  a.setFriction(0.1);  // changed during the run: must survive the restart
  a.run(3000);
  BinaryWriter w;
  a.saveState(w);
  a.run(2000);
  BinaryReader r(w.bytes(), "memory");
  Simulation b = Simulation::restoreState(r);
  EXPECT_TRUE(r.atEnd());
  b.run(2000);
  ASSERT_GT(a.contacts().activeCount(), 500u);
  ASSERT_GT(a.profile().rebuilds, 0);
  EXPECT_TRUE(test::sameBits(a.particles().pos, b.particles().pos));
  EXPECT_TRUE(test::sameBits(a.particles().vel, b.particles().vel));
  EXPECT_TRUE(test::sameBits(a.particles().angVel, b.particles().angVel));
  EXPECT_TRUE(test::sameBits(a.contacts().history, b.contacts().history));
  EXPECT_EQ(std::memcmp(a.cell().matrix().data(), b.cell().matrix().data(), sizeof(Mat3)), 0);
  EXPECT_EQ(a.energy().balance(), b.energy().balance());
  EXPECT_EQ(b.materials()[0].friction, 0.1);
}

TEST(Restart, TruncatedStateIsAClearErrorNotACrash) {
  ParticleStore p;
  p.add(Vec3(1e-3, 1e-3, 1e-3), 0.5e-3, 2500, 0);
  Simulation a(std::move(p), PeriodicCell::box(5e-3, 5e-3, 5e-3), {Material::paperGlass()}, NumericsSettings{});
  BinaryWriter w;
  a.saveState(w);
  for (std::size_t cut : {std::size_t(0), std::size_t(3), w.bytes().size() / 2, w.bytes().size() - 1}) {
    const std::string part = w.bytes().substr(0, cut);
    BinaryReader r(part, "ckpt.bin");
    try {
      (void)Simulation::restoreState(r);
      FAIL() << "accepted a truncated state of " << cut << " bytes";
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find("ckpt.bin"), std::string::npos);
      EXPECT_NE(std::string(e.what()).find("byte"), std::string::npos);
    }
  }
}
