// Set-up pieces: size distributions, the gas generator, numerics validation and their errors.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "core/errors.hpp"
#include "core/gas_generator.hpp"
#include "core/simulation.hpp"

using namespace fl;

TEST(SizeDistributionTest, PaperBeadsHaveSevenSizesAndMeanOnePointOneMillimetre) {
  const auto psd = SizeDistribution::paperGlassBeads();
  EXPECT_EQ(psd.diameters.size(), 7u);
  EXPECT_NEAR(psd.numberMeanDiameter(), 1.1e-3, 1e-12);
  const auto r = sampleRadii(psd, 4000, 1);
  ASSERT_EQ(r.size(), 4000u);
  std::map<double, int> counts;
  double mean = 0;
  for (double x : r) {
    ++counts[x];
    mean += 2 * x / 4000;
  }
  EXPECT_EQ(counts.size(), 7u);
  for (auto& [d, c] : counts) EXPECT_NEAR(c, 4000.0 / 7, 1.0);
  EXPECT_NEAR(mean, 1.1e-3, 1e-6);
}

TEST(SizeDistributionTest, MassFractionsConvertToNumberFractions) {
  SizeDistribution p{{1e-3, 2e-3}, {0.5, 0.5}, SizeDistribution::Basis::Mass};
  const auto w = p.numberFractions();
  EXPECT_NEAR(w[0] / w[1], 8.0, 1e-12);
}

TEST(SizeDistributionTest, BadInputNamesTheField) {
  SizeDistribution p{{1e-3, 2e-3}, {0.5}, SizeDistribution::Basis::Number};
  EXPECT_THROW(p.validate(), InputError);
  try {
    p.validate();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("fractions"), std::string::npos);
  }
  SizeDistribution q{{-1e-3}, {1}, SizeDistribution::Basis::Number};
  EXPECT_THROW(q.validate(), InputError);
}

TEST(GasGenerator, NoOverlapsChosenFractionAndSeeded) {
  GasSpec g;
  g.count = 800;
  g.solidFraction = 0.3;
  g.seed = 42;
  const Packing a = generateGas(g);
  EXPECT_NEAR(a.particles.solidVolume() / a.cell.volume(), 0.3, 1e-12);
  NumericsSettings num;
  Simulation sim(a.particles, a.cell, {Material::paperGlass()}, num);
  EXPECT_EQ(sim.contacts().activeCount(), 0u);
  const Packing b = generateGas(g);
  EXPECT_EQ(a.particles.pos, b.particles.pos);
  g.seed = 43;
  EXPECT_NE(generateGas(g).particles.pos, a.particles.pos);
}

TEST(GasGenerator, TooDenseIsAClearError) {
  GasSpec g;
  g.solidFraction = 0.6;
  EXPECT_THROW(generateGas(g), InputError);
}

TEST(NumericsValidation, EachBadSettingIsRejectedWithItsName) {
  auto expectField = [](NumericsSettings n, const std::string& field) {
    try {
      n.validate();
      ADD_FAILURE() << field << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  NumericsSettings n;
  n.timeStepFactor = 1.5;
  expectField(n, "timeStepFactor");
  n = {};
  n.localDamping = 1.0;
  expectField(n, "localDamping");
  n = {};
  n.restitution = 0.0;
  expectField(n, "restitution");
  n.restitution = 0.009;  // below kMinRestitution: the damping ratio would grow without bound
  expectField(n, "restitution");
  n = {};
  n.densityScale = 0.5;
  expectField(n, "densityScale");
  n = {};
  n.threads = 0;
  expectField(n, "threads");
}

TEST(TimeStep, RayleighStepOfThePaperGlass) {
  // platform.md: about 0.57 us for R = 0.55 mm glass and 0.41 us for R = 0.40 mm
  ParticleStore p;
  p.add(Vec3::Zero(), 0.55e-3, 2570, 0);
  EXPECT_NEAR(rayleighTimeStep(p, {Material::paperGlass()}, 1.0), 0.57e-6, 0.01e-6);
  p.add(Vec3::Zero(), 0.40e-3, 2570, 0);
  EXPECT_NEAR(rayleighTimeStep(p, {Material::paperGlass()}, 1.0), 0.41e-6, 0.01e-6);
  EXPECT_NEAR(rayleighTimeStep(p, {Material::paperGlass()}, 4.0), 0.82e-6, 0.02e-6);
}
