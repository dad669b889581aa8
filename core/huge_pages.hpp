// Large arrays in 2 MiB pages (issue 6, scaling). With 4 KiB pages the large states' scattered reads (a pair's
// partner lines, the kick's second-side result lines) miss the TLB as well as the caches: at 256 000 spheres
// the engine's arrays span ~150 MB, ~37 000 small pages against the core's few thousand TLB entries. The kernel
// here grants transparent huge pages only to ranges that ask for them (madvise), so the hot arrays of the
// particle and contact stores are allocated through HugePageAllocator: an allocation of at least
// kHugePageThreshold bytes is mapped on its own, aligned to 2 MiB and advised MADV_HUGEPAGE before its first
// touch; smaller ones (every array of a 4000-sphere scene: its pair lines take 0.8 MB) come from std::allocator as
// before. Only where the memory sits changes, never a value: the bits are those of std::vector. On the Zen 4 host
// the 1-thread step ran 10 % faster at 256 000 spheres and 4.5 % at 1M (docs/performance.md, twenty-fourth
// session); 2 MiB pages for the small arrays too were level at 4000 spheres.
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory>
#include <new>
#include <vector>

namespace fl {

inline constexpr std::size_t kHugePageBytes = std::size_t{2} << 20;
inline constexpr std::size_t kHugePageThreshold = std::size_t{4} << 20;  // smaller arrays stay in the heap

// Maps bytes (>= kHugePageThreshold) aligned to kHugePageBytes and asks for huge pages; returns nullptr when the
// system refuses the mapping. Where huge pages are unknown (not Linux) it is aligned heap memory.
void* mapHugePages(std::size_t bytes);
void unmapHugePages(void* p, std::size_t bytes);

template <class T>
struct HugePageAllocator {
  using value_type = T;
  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    if (n > std::size_t(-1) / sizeof(T)) throw std::bad_array_new_length();
    if (n * sizeof(T) < kHugePageThreshold) return std::allocator<T>{}.allocate(n);
    void* p = mapHugePages(n * sizeof(T));
    if (p == nullptr) throw std::bad_alloc();
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t n) noexcept {
    if (n * sizeof(T) < kHugePageThreshold) return std::allocator<T>{}.deallocate(p, n);
    unmapHugePages(p, n * sizeof(T));
  }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const noexcept { return true; }
};

// A hot array of the engine: a std::vector whose large allocations sit in huge pages.
template <class T>
using HugeVector = std::vector<T, HugePageAllocator<T>>;

// Makes v's capacity fit an array about to hold n elements, for the arrays a neighbour-list rebuild writes again
// and again: a capacity in [n, n + n/4 + 64] is kept (the arrays are reused, so a rebuild writes no fresh memory:
// on the VMs we measure on a fresh page costs ~1.6 ms a MB when first written, docs/performance.md, fortieth
// session); outside it the array is made again with room for n + n/16 + 64 (a list a little longer next time still
// fits), every element of it written once here, and the first min(size, n) elements copied.
template <class V>
void fitCapacity(V& v, std::size_t n) {
  const std::size_t capacity = v.capacity();
  if (capacity >= n && capacity <= n + n / 4 + 64) return;
  const std::size_t kept = std::min(v.size(), n);
  V fresh;
  fresh.reserve(n + n / 16 + 64);
  fresh.resize(fresh.capacity());
  std::copy(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(kept), fresh.begin());
  fresh.resize(kept);
  v.swap(fresh);
}

}  // namespace fl
