// Runs of a loop's items claimed by their owner and stolen by its neighbour (work_stealing.hpp).
#include "work_stealing.hpp"

#include "spin_wait.hpp"

#include <algorithm>
#include <cassert>

namespace fl {

namespace {
constexpr std::uint64_t pack(std::uint64_t front, std::uint64_t back) { return back << 32 | front; }
constexpr std::uint64_t frontOf(std::uint64_t w) { return w & 0xffffffffu; }
constexpr std::uint64_t backOf(std::uint64_t w) { return w >> 32; }
}  // namespace

void StealingRanges::reset(const std::vector<std::size_t>& bounds, std::size_t grain) {
  assert(bounds.size() >= 2 && bounds.back() < (std::size_t{1} << 32) && grain >= 1);
  const int nt = static_cast<int>(bounds.size()) - 1;
  if (nt > m_capacity) {
    m_shares = std::make_unique<Share[]>(static_cast<std::size_t>(nt));
    m_capacity = nt;
  }
  m_threads = nt;
  m_grain = grain;
  for (int t = 0; t < nt; ++t) {
    m_shares[t].bounds.store(pack(bounds[t], bounds[t + 1]), std::memory_order_relaxed);
    m_shares[t].stolen.store(0, std::memory_order_relaxed);
    m_shares[t].end = static_cast<std::uint32_t>(bounds[t + 1]);
    m_shares[t].takenDone.store(0, std::memory_order_relaxed);
  }
}

std::size_t StealingRanges::stolen() const {
  std::size_t n = 0;
  for (int t = 0; t < m_threads; ++t) n += m_shares[t].stolen.load(std::memory_order_relaxed);
  return n;
}

bool StealingRanges::claimFront(Share& s, std::size_t& begin, std::size_t& end) const {
  std::uint64_t w = s.bounds.load(std::memory_order_relaxed);
  for (;;) {
    const std::uint64_t f = frontOf(w), b = backOf(w);
    if (f >= b) return false;
    const std::uint64_t e = std::min(b, f + m_grain);
    if (s.bounds.compare_exchange_weak(w, pack(e, b), std::memory_order_relaxed)) {
      begin = f, end = e;
      return true;
    }
  }
}

bool StealingRanges::claimBack(Share& s, std::size_t& begin, std::size_t& end) const {
  std::uint64_t w = s.bounds.load(std::memory_order_relaxed);
  for (;;) {
    const std::uint64_t f = frontOf(w), b = backOf(w);
    if (f >= b) return false;
    const std::uint64_t q = b - std::min(b - f, m_grain);
    if (s.bounds.compare_exchange_weak(w, pack(f, q), std::memory_order_relaxed)) {
      s.stolen.fetch_add(1, std::memory_order_relaxed);
      begin = q, end = b;
      return true;
    }
  }
}

bool StealingRanges::next(int t, std::size_t& begin, std::size_t& end) {
  return nextOwn(t, begin, end) || nextTaken(t, begin, end);
}

bool StealingRanges::nextOwn(int t, std::size_t& begin, std::size_t& end) {
  return claimFront(m_shares[t], begin, end);
}

bool StealingRanges::nextTaken(int t, std::size_t& begin, std::size_t& end) {
  return m_threads >= 2 && claimBack(m_shares[victimOf(t)], begin, end);
}

void StealingRanges::doneTaken(int t, std::size_t items) {
  // release: the run's writes are visible to the owner that sees the count (waitForTakers)
  m_shares[victimOf(t)].takenDone.fetch_add(items, std::memory_order_release);
}

void StealingRanges::waitForTakers(int t) const {
  const Share& s = m_shares[t];
  // once the share is empty (front >= back) no run can be taken any more: the taken items are [back, end)
  const std::uint64_t w = s.bounds.load(std::memory_order_relaxed);
  assert(frontOf(w) >= backOf(w));
  const std::uint64_t taken = s.end - backOf(w);
  for (int turn = 0; s.takenDone.load(std::memory_order_acquire) < taken; ++turn) backOff(turn, kSpins);
}

std::uint64_t RoundProgress::beginRound(int threads, int cores) {
  // with more threads than cores the owner may be waiting for a waiter's core: yield almost at once, as
  // libgomp's barriers do
  m_spins = spinsFor(threads, cores);
  if (threads > m_capacity) {
    m_slots = std::make_unique<Slot[]>(static_cast<std::size_t>(threads));  // every signal at round 0
    m_capacity = threads;
    m_round = 0;
  }
  if (++m_round >= m_restartAt) {  // after ~4e9 rounds: start again from round 1
    for (int t = 0; t < m_capacity; ++t) m_slots[t].value.store(0, std::memory_order_relaxed);
    m_round = 1;
  }
  return m_round;
}

std::uint32_t RoundProgress::waitFor(int s, std::uint64_t round, std::uint32_t done) const {
  assert(s < m_capacity);
  const std::uint64_t target = round << 32 | done;
  std::uint64_t value;
  for (int turn = 0; (value = m_slots[s].value.load(std::memory_order_acquire)) < target; ++turn)
    backOff(turn, m_spins);
  assert(value >> 32 == round);  // the owner publishes no later round before the region ends
  return static_cast<std::uint32_t>(value);
}

}  // namespace fl
