// HugePageAllocator (core/huge_pages.hpp): the engine's hot arrays come from it. Checked here: arrays below the
// threshold stay in the heap, larger ones are aligned to 2 MiB and (on Linux with transparent huge pages) advised
// for huge pages before their first touch, and a HugeVector keeps its values through growth across the
// threshold, copies, moves and shrinking, as a std::vector does.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <type_traits>

#include "core/contact_store.hpp"
#include "core/huge_pages.hpp"
#include "core/particle_store.hpp"

using namespace fl;

namespace {

std::uintptr_t address(const void* p) { return reinterpret_cast<std::uintptr_t>(p); }

#if defined(__linux__)
// The VmFlags line of the mapping of /proc/self/smaps that holds p ("" when none does).
std::string vmFlagsOf(const void* p) {
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    std::uintptr_t lo = 0, hi = 0;
    char dash = 0;
    std::istringstream head(line);
    if (head >> std::hex >> lo >> dash >> hi && dash == '-') {
      inside = address(p) >= lo && address(p) < hi;
    } else if (inside && line.rfind("VmFlags:", 0) == 0) {
      return line;
    }
  }
  return "";
}

bool kernelHasTransparentHugePages() {
  std::ifstream enabled("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string modes;
  return std::getline(enabled, modes) && modes.find("[never]") == std::string::npos;
}
#endif

}  // namespace

// The arrays the step sweeps at large N come from the allocator (docs/performance.md, twenty-fourth session).
template <class V>
constexpr bool kHuge = std::is_same_v<typename V::allocator_type, HugePageAllocator<typename V::value_type>>;
static_assert(kHuge<decltype(ParticleStore::pos)> && kHuge<decltype(ParticleStore::vel)> &&
              kHuge<decltype(ParticleStore::angVel)> && kHuge<decltype(ParticleStore::radius)> &&
              kHuge<decltype(ParticleStore::invMass)> && kHuge<decltype(ParticleStore::invInertia)>);
static_assert(kHuge<decltype(ContactStore::first)> && kHuge<decltype(ContactStore::second)> &&
              kHuge<decltype(ContactStore::image)> && kHuge<decltype(ContactStore::history)> &&
              kHuge<decltype(ContactStore::result)> && kHuge<decltype(ContactStore::adjEntry)> &&
              kHuge<decltype(ContactStore::touched)>);

TEST(HugePages, SmallArraysStayInTheHeapAndLargeOnesAreAlignedToAHugePage) {
  HugeVector<double> small(1000, 1.0);
  HugeVector<double> large(kHugePageThreshold / sizeof(double) + 1, 2.0);
  EXPECT_EQ(address(large.data()) % kHugePageBytes, 0u) << "a large array starts on a huge page";
#if defined(__linux__)
  EXPECT_EQ(vmFlagsOf(small.data()).find(" hg"), std::string::npos) << "the heap is not advised";
  if (kernelHasTransparentHugePages()) {
    EXPECT_NE(vmFlagsOf(large.data()).find(" hg"), std::string::npos)
        << "the large array's mapping was not advised MADV_HUGEPAGE: " << vmFlagsOf(large.data());
  }
#endif
  for (double v : small) ASSERT_EQ(v, 1.0);
  for (double v : large) ASSERT_EQ(v, 2.0);
}

TEST(HugePages, AVectorKeepsItsValuesThroughGrowthCopiesMovesAndShrinking) {
  const std::size_t n = 3 * kHugePageThreshold / sizeof(std::int64_t);  // grows from the heap into huge pages
  HugeVector<std::int64_t> v;
  for (std::size_t k = 0; k < n; ++k) v.push_back(static_cast<std::int64_t>(k * 7 + 1));
  EXPECT_EQ(address(v.data()) % kHugePageBytes, 0u);
  HugeVector<std::int64_t> copy = v;
  HugeVector<std::int64_t> moved = std::move(copy);
  ASSERT_EQ(moved.size(), n);
  for (std::size_t k = 0; k < n; ++k) ASSERT_EQ(moved[k], static_cast<std::int64_t>(k * 7 + 1)) << k;
  moved.resize(100);  // back below the threshold: the small array comes from the heap again
  moved.shrink_to_fit();
  ASSERT_EQ(moved.size(), 100u);
  for (std::size_t k = 0; k < 100; ++k) ASSERT_EQ(moved[k], static_cast<std::int64_t>(k * 7 + 1));
  v.clear();
  v.shrink_to_fit();
  EXPECT_EQ(v.capacity(), 0u);
}

// fitCapacity: the arrays a rebuild writes again keep their memory while it fits, and are made again otherwise.
TEST(HugePages, FitCapacityKeepsAFittingArrayAndRemakesOthersWithTheirFirstValues) {
  HugeVector<std::int32_t> v;
  fitCapacity(v, 1000);  // empty: made with room for 1000 + 1000/16 + 64
  EXPECT_EQ(v.size(), 0u);
  EXPECT_EQ(v.capacity(), 1000u + 62u + 64u);
  for (int k = 0; k < 1000; ++k) v.push_back(k);
  const std::int32_t* kept = v.data();
  fitCapacity(v, 1100);  // still in [n, n + n/4 + 64]: the same memory, the values untouched
  fitCapacity(v, 900);
  EXPECT_EQ(v.data(), kept);
  EXPECT_EQ(v.size(), 1000u);
  fitCapacity(v, 2000);  // too small for 2000: remade, the values kept
  EXPECT_GE(v.capacity(), 2000u);
  EXPECT_LE(v.capacity(), 2000u + 2000u / 4 + 64u);
  ASSERT_EQ(v.size(), 1000u);
  for (int k = 0; k < 1000; ++k) ASSERT_EQ(v[k], k);
  fitCapacity(v, 100);  // far too large for 100: remade, the first 100 values kept
  EXPECT_LE(v.capacity(), 100u + 100u / 4 + 64u);
  ASSERT_EQ(v.size(), 100u);
  for (int k = 0; k < 100; ++k) ASSERT_EQ(v[k], k);
}
