// libFuzzer target: readLammpsData on arbitrary bytes. Rejections must name the file and the byte offset;
// an accepted packing must have >= 1 particle, finite positions inside the cell, positive finite radii
// and densities, finite velocities.
#include <cmath>

#include "core/packing_io.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string& path = fl::fuzz::scratchPath("lammps");
  fl::fuzz::writeScratch(path, data, size);
  fl::Packing pk;
  if (!fl::fuzz::expectCleanRejection(path, true, [&] { pk = fl::readLammpsData(path, 0); })) return 0;
  const auto& p = pk.particles;
  if (p.size() == 0) fl::fuzz::fail("readLammpsData accepted a packing with no particles");
  for (std::size_t i = 0; i < p.size(); ++i) {
    const fl::Vec3 s = pk.cell.reduced(p.pos[i]);
    if (!p.pos[i].allFinite() || !p.vel[i].allFinite() || !p.angVel[i].allFinite() ||
        !(std::isfinite(p.radius[i]) && p.radius[i] > 0) || !(std::isfinite(p.invMass[i]) && p.invMass[i] > 0))
      fl::fuzz::fail("readLammpsData accepted a non-finite or non-positive value");
    for (int k = 0; k < 3; ++k)
      if (!(s[k] >= -1e-9 && s[k] <= 1 + 1e-9)) fl::fuzz::fail("readLammpsData left a particle outside the cell");
  }
  return 0;
}
