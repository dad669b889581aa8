// Shared by the libFuzzer targets: the contract every reader in core/ promises for hostile input.
//   - a rejected input throws fl::InputError or fl::IoError whose message names the file (and, where the
//     reader promises it, the byte offset); any other exception, a crash, a hang or a leak is a bug;
//   - an accepted input yields a well-formed object (the target checks its invariants).
// A broken contract calls fail(), which aborts, so libFuzzer records the input as a crash.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <string_view>

#include "core/errors.hpp"

namespace fl::fuzz {

[[noreturn]] inline void fail(const std::string& what) {
  std::fprintf(stderr, "\n=== FUZZ CONTRACT VIOLATION: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

// A per-process scratch file; the readers under test take paths, not buffers.
inline const std::string& scratchPath(const char* stem) {
  static const std::string path = [&] {
    const char* dir = std::getenv("TMPDIR");
    return std::string(dir && *dir ? dir : "/tmp") + "/fl-fuzz-" + stem + "-" + std::to_string(::getpid());
  }();
  return path;
}

inline void writeScratch(const std::string& path, const std::uint8_t* data, std::size_t size) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) fail("cannot write scratch file " + path);
  if (size && std::fwrite(data, 1, size, f) != size) fail("short write to " + path);
  std::fclose(f);
}

// Runs <body>; accepts only InputError/IoError whose message names <file> (and "byte N" if <wantOffset>).
// Returns true if <body> completed without throwing.
template <class F>
bool expectCleanRejection(const std::string& file, bool wantOffset, F&& body) {
  try {
    body();
    return true;
  } catch (const fl::InputError& e) {
    const std::string_view m = e.what();
    if (m.find(file) == std::string_view::npos) fail("InputError does not name the file '" + file + "': " + e.what());
    if (wantOffset && m.find("byte ") == std::string_view::npos)
      fail("InputError does not give the byte offset: " + std::string(e.what()));
  } catch (const fl::IoError& e) {
    const std::string_view m = e.what();
    if (m.find(file) == std::string_view::npos) fail("IoError does not name the file '" + file + "': " + e.what());
    if (wantOffset && m.find("byte ") == std::string_view::npos && m.find("checksum") == std::string_view::npos &&
        m.find("version") == std::string_view::npos && m.find("payload") == std::string_view::npos)
      fail("IoError does not give the byte offset: " + std::string(e.what()));
  } catch (const fl::Error& e) {
    fail(std::string("fl::Error that is neither InputError nor IoError: ") + e.what());
  } catch (const std::exception& e) {
    fail(std::string("non-FabricLab exception escaped the reader: ") + e.what());
  } catch (...) {
    fail("unknown exception escaped the reader");
  }
  return false;
}

}  // namespace fl::fuzz
