// Huge-page mappings for HugePageAllocator (huge_pages.hpp).
#include "huge_pages.hpp"

#include <cstdint>
#include <cstdlib>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace fl {

namespace {
std::size_t roundUp(std::size_t bytes) { return (bytes + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes; }
}  // namespace

#if defined(__linux__)

// mmap gives 4 KiB alignment only: map one huge page more, then unmap the unaligned head and the tail.
void* mapHugePages(std::size_t bytes) {
  const std::size_t length = roundUp(bytes);
  const std::size_t span = length + kHugePageBytes;
  void* raw = ::mmap(nullptr, span, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (raw == MAP_FAILED) return nullptr;
  const auto base = reinterpret_cast<std::uintptr_t>(raw);
  const std::uintptr_t aligned = (base + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
  if (aligned > base) ::munmap(raw, aligned - base);
  const std::uintptr_t end = base + span;
  if (end > aligned + length) ::munmap(reinterpret_cast<void*>(aligned + length), end - (aligned + length));
  void* p = reinterpret_cast<void*>(aligned);
#if defined(MADV_HUGEPAGE)
  ::madvise(p, length, MADV_HUGEPAGE);  // a hint: where the kernel refuses, the pages stay small
#endif
  return p;
}

void unmapHugePages(void* p, std::size_t bytes) { ::munmap(p, roundUp(bytes)); }

#else

void* mapHugePages(std::size_t bytes) { return std::aligned_alloc(kHugePageBytes, roundUp(bytes)); }
void unmapHugePages(void* p, std::size_t) { std::free(p); }

#endif

}  // namespace fl
