// Little binary serialisation for checkpoints: plain-old-data values and vectors appended to a byte
// buffer, read back with bounds checks. Every read names the field, so a truncated or corrupted file
// gives "checkpoint <file>: truncated at byte N reading <field>" instead of a crash.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "errors.hpp"

namespace fl {

class BinaryWriter {
 public:
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_destructible_v<T> && std::is_standard_layout_v<T>);  // POD-like (Eigen fixed-size included)
    const auto* b = reinterpret_cast<const char*>(&v);
    m_buf.append(b, sizeof(T));
  }
  template <class T, class A>
  void putVector(const std::vector<T, A>& v) {
    static_assert(std::is_trivially_destructible_v<T> && std::is_standard_layout_v<T>);  // POD-like (Eigen fixed-size included)
    put<std::uint64_t>(v.size());
    m_buf.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  void putString(const std::string& s) {
    put<std::uint64_t>(s.size());
    m_buf.append(s);
  }
  const std::string& bytes() const { return m_buf; }

 private:
  std::string m_buf;
};

// Reads from <bytes>, which must outlive the reader; a temporary (e.g. bytes.substr(...)) is copied into
// the reader instead, so `BinaryReader r(s.substr(a, b), ...)` cannot leave a dangling reference.
// Not copyable or movable (it may point into its own storage).
class BinaryReader {
 public:
  BinaryReader(const std::string& bytes, std::string source, std::size_t baseOffset = 0)
      : m_buf(bytes), m_source(std::move(source)), m_base(baseOffset) {}
  BinaryReader(std::string&& bytes, std::string source, std::size_t baseOffset = 0)
      : m_own(std::move(bytes)), m_buf(m_own), m_source(std::move(source)), m_base(baseOffset) {}
  BinaryReader(const BinaryReader&) = delete;
  BinaryReader& operator=(const BinaryReader&) = delete;

  template <class T>
  T get(const char* field) {
    static_assert(std::is_trivially_destructible_v<T> && std::is_standard_layout_v<T>);  // POD-like (Eigen fixed-size included)
    need(sizeof(T), field);
    if constexpr (std::is_same_v<T, bool>) {  // a byte other than 0/1 is corruption (and UB to load as bool)
      const auto b = static_cast<unsigned char>(m_buf[m_pos]);
      if (b > 1) fail(std::string("invalid value ") + std::to_string(b) + " for the flag " + field);
    }
    T v;
    std::memcpy(static_cast<void*>(&v), m_buf.data() + m_pos, sizeof(T));
    m_pos += sizeof(T);
    return v;
  }
  template <class T, class A = std::allocator<T>>
  std::vector<T, A> getVector(const char* field, std::uint64_t maxCount = 1ull << 31) {
    const auto n = get<std::uint64_t>(field);
    if (n > maxCount || n * sizeof(T) > m_buf.size() - m_pos)
      fail(std::string("implausible length ") + std::to_string(n) + " for " + field);
    std::vector<T, A> v(n);
    if (n) std::memcpy(static_cast<void*>(v.data()), m_buf.data() + m_pos, n * sizeof(T));
    m_pos += n * sizeof(T);
    return v;
  }
  // getVector into `into`, whatever its allocator (the engine's hot arrays are HugeVectors, huge_pages.hpp)
  template <class T, class A>
  void getVectorInto(std::vector<T, A>& into, const char* field, std::uint64_t maxCount = 1ull << 31) {
    into = getVector<T, A>(field, maxCount);
  }
  std::string getString(const char* field) {
    auto v = getVector<char>(field, 1ull << 30);
    return std::string(v.begin(), v.end());
  }
  std::size_t offset() const { return m_base + m_pos; }
  bool atEnd() const { return m_pos == m_buf.size(); }
  [[noreturn]] void fail(const std::string& what) const {
    throw IoError(m_source + ": " + what + " (byte " + std::to_string(offset()) + ")");
  }

 private:
  void need(std::size_t n, const char* field) const {
    if (m_buf.size() - m_pos < n) fail(std::string("truncated while reading ") + field);
  }
  std::string m_own;  // the bytes, when the reader was given a temporary
  const std::string& m_buf;
  std::string m_source;
  std::size_t m_base;
  std::size_t m_pos = 0;
};

// FNV-1a 64-bit checksum.
inline std::uint64_t fnv1a64(const std::string& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace fl
