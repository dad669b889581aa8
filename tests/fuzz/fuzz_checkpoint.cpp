// libFuzzer target: Runner::fromCheckpoint on a file. A random mutation of a checkpoint almost always breaks
// its FNV-1a checksum, which would keep the fuzzer at the door; so the first input byte picks the mode:
//   even: the remaining bytes are written as they are (magic, version, size and checksum checks);
//   odd:  the remaining bytes are a payload; the target frames it with a valid header and checksum, so
//         mutations reach the payload parser (embedded scene, runner state, simulation state).
// Rejections must be InputError/IoError naming the file (and the byte offset for framing/payload errors).
#include <cstring>

#include "core/binary_io.hpp"
#include "core/runner.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string& path = fl::fuzz::scratchPath("ckpt");
  if (data[0] & 1) {
    static constexpr char kMagic[] = "FABRICLAB-CHECKPOINT";  // as in core/runner.cpp, NUL included
    const std::string payload(reinterpret_cast<const char*>(data + 1), size - 1);
    fl::BinaryWriter w;
    w.put<std::uint32_t>(1);
    w.put<std::uint64_t>(payload.size());
    std::string file(kMagic, sizeof(kMagic));
    file += w.bytes();
    file += payload;
    fl::BinaryWriter tail;
    tail.put(fl::fnv1a64(payload));
    file += tail.bytes();
    fl::fuzz::writeScratch(path, reinterpret_cast<const std::uint8_t*>(file.data()), file.size());
  } else {
    fl::fuzz::writeScratch(path, data + 1, size - 1);
  }
  fl::fuzz::expectCleanRejection(path, false, [&] {
    fl::Runner r = fl::Runner::fromCheckpoint(path);
    if (r.simulation().particles().size() == 0) fl::fuzz::fail("fromCheckpoint accepted a state with no particles");
  });
  return 0;
}
