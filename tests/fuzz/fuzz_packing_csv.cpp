// libFuzzer target: readPackingCsv on arbitrary bytes. The first byte picks the overload (odd: the caller
// passes a cell, as for files without a '# cell' line). Rejections must name the file and the byte offset;
// an accepted packing must have >= 1 particle, finite positions inside the cell, positive finite radii.
#include <cmath>

#include "core/packing_io.hpp"
#include "fuzz_support.hpp"

namespace {
void checkPacking(const fl::Packing& pk, const char* who) {
  const std::size_t n = pk.particles.size();
  if (n == 0) fl::fuzz::fail(std::string(who) + ": accepted a packing with no particles");
  for (std::size_t i = 0; i < n; ++i) {
    const fl::Vec3 s = pk.cell.reduced(pk.particles.pos[i]);
    if (!pk.particles.pos[i].allFinite() || !(std::isfinite(pk.particles.radius[i]) && pk.particles.radius[i] > 0))
      fl::fuzz::fail(std::string(who) + ": accepted a non-finite position or a bad radius");
    for (int k = 0; k < 3; ++k)
      if (!(s[k] >= -1e-9 && s[k] <= 1 + 1e-9)) fl::fuzz::fail(std::string(who) + ": particle left outside the cell");
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const bool givenCell = data[0] & 1;
  const std::string& path = fl::fuzz::scratchPath("csv");
  fl::fuzz::writeScratch(path, data + 1, size - 1);
  fl::Packing pk;
  const fl::PeriodicCell cell = fl::PeriodicCell::box(0.01, 0.01, 0.01);
  if (fl::fuzz::expectCleanRejection(path, true, [&] {
        pk = givenCell ? fl::readPackingCsv(path, 2570.0, 0, cell) : fl::readPackingCsv(path, 2570.0, 0);
      }))
    checkPacking(pk, "readPackingCsv");
  return 0;
}
