// Streaming (non-temporal) stores of whole 64-byte lines (issue 6, scaling). A plain store first reads the
// line it writes into the cache (the read for ownership); once the state outgrows the caches, the contact
// pass's result lines come from memory only to be overwritten, and leave the cache again long before the
// kick reads them. A streaming store writes the line to memory without reading it. Only for lines that are
// written whole and not read again soon by this core; streaming stores are weakly ordered, so a thread
// calls streamFence() before other threads may read what it streamed (before the end of a parallel region).
#pragma once

#include <cstddef>
#include <cstring>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace fl {

// Writes line[0..7] to the 64-byte aligned dst, bypassing the cache where the target has streaming stores
// (x86-64: one AVX-512 store, two AVX stores or four SSE2 stores, which the write-combining buffer joins into
// one line); elsewhere a plain copy. The bits written are those of line either way.
inline void streamLine(void* dst, const double* line) {
  auto* d = static_cast<double*>(dst);
#if defined(__AVX512F__)
  _mm512_stream_pd(d, _mm512_loadu_pd(line));
#elif defined(__AVX__)
  _mm256_stream_pd(d, _mm256_loadu_pd(line));
  _mm256_stream_pd(d + 4, _mm256_loadu_pd(line + 4));
#elif defined(__SSE2__)
  for (int k = 0; k < 8; k += 2) _mm_stream_pd(d + k, _mm_loadu_pd(line + k));
#else
  std::memcpy(d, line, 8 * sizeof(double));
#endif
}

// Writes `words` 8-byte words from src to the 8-byte aligned dst by streaming stores (x86-64), for runs of
// entries smaller than a line that the caller writes in ascending order, so that the write-combining buffer
// still gathers whole lines; elsewhere a plain copy. The bits written are those of src either way.
inline void streamWords(void* dst, const void* src, int words) {
#if defined(__x86_64__)
  auto* d = static_cast<long long*>(dst);
  for (int k = 0; k < words; ++k) {
    long long w;
    std::memcpy(&w, static_cast<const char*>(src) + 8 * k, sizeof w);
    _mm_stream_si64(d + k, w);
  }
#else
  std::memcpy(dst, src, 8 * static_cast<std::size_t>(words));
#endif
}

// Orders this thread's streaming stores before its later stores (and so before a barrier's).
inline void streamFence() {
#if defined(__SSE2__)
  _mm_sfence();
#endif
}

}  // namespace fl
