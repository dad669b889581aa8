// Headless command (core only; no Qt, no VTK).
#include <cstdio>

#include "core/gas_generator.hpp"
#include "core/simulation.hpp"

int main() {
  fl::GasSpec g;
  g.count = 1000;
  fl::Packing pk = fl::generateGas(g);
  fl::Simulation sim(std::move(pk.particles), pk.cell, {fl::Material::paperGlass()}, fl::NumericsSettings{});
  sim.run(100);
  std::printf("steps %ld\n", sim.stepCount());
}
