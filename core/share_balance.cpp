// Each thread's share from its measured costs (share_balance.hpp).
#include "share_balance.hpp"

#include <algorithm>
#include <cmath>

#include "work_stealing.hpp"  // staticBegin

namespace fl {

double predictedStep(const std::vector<ThreadCosts>& cost, const std::vector<std::size_t>& edges,
                     const std::vector<std::size_t>& firstParticle) {
  double pass = 0.0, kick = 0.0;
  for (std::size_t t = 0; t + 1 < edges.size() && t < cost.size(); ++t) {
    const auto chunks = static_cast<double>(edges[t + 1] - edges[t]);
    const auto particles = static_cast<double>(firstParticle[edges[t + 1]] - firstParticle[edges[t]]);
    pass = std::max(pass, cost[t].perChunk * chunks);
    kick = std::max(kick, cost[t].perParticle * particles);
  }
  return pass + kick;
}

std::vector<std::size_t> bestEdges(const std::vector<ThreadCosts>& cost, const std::vector<std::size_t>& firstParticle,
                                   std::vector<std::size_t> start) {
  const std::size_t nt = start.size() - 1, chunks = start.back();
  if (nt < 2 || chunks < nt) return start;
  std::vector<std::size_t> best = start, e = start;
  double bestTime = predictedStep(cost, best, firstParticle);
  if (nt == 2) {
    for (std::size_t k = 1; k < chunks; ++k) {
      e[1] = k;
      const double time = predictedStep(cost, e, firstParticle);
      if (time < bestTime) bestTime = time, best = e;
    }
    return best;
  }
  // more threads: one edge one chunk at a time, while the prediction improves (at most a pass over the chunks)
  for (std::size_t moves = 0; moves < chunks; ++moves) {
    bool improved = false;
    for (std::size_t t = 1; t < nt; ++t)
      for (const int step : {-1, 1}) {
        e = best;
        const std::size_t k = e[t] + static_cast<std::size_t>(step);
        if (k <= e[t - 1] || k >= e[t + 1]) continue;  // every thread keeps at least one chunk
        e[t] = k;
        const double time = predictedStep(cost, e, firstParticle);
        if (time < bestTime) bestTime = time, best = e, improved = true;
      }
    if (!improved) break;
  }
  return best;
}

std::vector<std::size_t> chunkBeginFor(const std::vector<double>& w, int threads, std::size_t chunks) {
  const int nt = std::max(1, threads);
  std::vector<std::size_t> begin(static_cast<std::size_t>(nt) + 1);
  for (int t = 0; t <= nt; ++t) begin[t] = staticBegin(t, nt, chunks);
  double total = 0.0;
  for (double x : w) total += x;
  if (w.size() != static_cast<std::size_t>(nt) || !(total > 0.0) || chunks < static_cast<std::size_t>(nt)) return begin;
  double cumulative = 0.0;
  for (int t = 1; t < nt; ++t) {
    cumulative += w[t - 1];
    const auto nearest = static_cast<std::size_t>(std::llround(cumulative / total * static_cast<double>(chunks)));
    // at least one chunk for each thread: after the ones before it, and room for the ones after it
    begin[t] = std::clamp(nearest, begin[t - 1] + 1, chunks - static_cast<std::size_t>(nt - t));
  }
  return begin;
}

void ShareBalance::fix(std::vector<double> shares) {
  m_measuring = false;
  m_fixed = std::move(shares);
  m_cost.clear();
}

void ShareBalance::measure() {
  m_measuring = true;
  m_fixed.clear();
  m_cost.clear();
  m_threads = 0;
}

void ShareBalance::prepare(int threads) {
  if (threads == m_threads) return;
  m_slots = std::make_unique<Slot[]>(static_cast<std::size_t>(std::max(threads, 1)));
  m_threads = threads;
  m_steps = 0;
  m_cost.clear();
}

std::vector<std::size_t> ShareBalance::edges(int threads, const std::vector<std::size_t>& firstParticle) const {
  const std::size_t chunks = firstParticle.empty() ? 0 : firstParticle.size() - 1;
  std::vector<std::size_t> even = chunkBeginFor(m_measuring ? std::vector<double>{} : m_fixed, threads, chunks);
  if (!m_measuring || m_cost.size() != static_cast<std::size_t>(threads)) return even;
  return bestEdges(m_cost, firstParticle, std::move(even));
}

bool ShareBalance::reconsider(const std::vector<std::size_t>& current, const std::vector<std::size_t>& firstParticle) {
  m_steps = 0;
  std::vector<ThreadCosts> window(static_cast<std::size_t>(m_threads));
  // every thread kicked particles, and every thread or none (a pass that is not timed: the
  // Mindlin-Deresiewicz law's) computed chunks
  int kicked = 0, passed = 0;
  for (int t = 0; t < m_threads; ++t) {
    const ThreadWork w = m_slots[t].work;
    m_slots[t].work = ThreadWork{};
    kicked += w.kickItems > 0.0;
    passed += w.passItems > 0.0;
    window[t] = {w.passItems > 0.0 ? w.passSeconds / w.passItems : 0.0,
                 w.kickItems > 0.0 ? w.kickSeconds / w.kickItems : 0.0};
  }
  if (kicked < m_threads || (passed != 0 && passed < m_threads)) return false;
  if (m_cost.size() != window.size()) {
    m_cost = window;
  } else {
    for (std::size_t t = 0; t < window.size(); ++t) {
      m_cost[t].perChunk += kSmoothing * (window[t].perChunk - m_cost[t].perChunk);
      m_cost[t].perParticle += kSmoothing * (window[t].perParticle - m_cost[t].perParticle);
    }
  }
  if (current.size() != window.size() + 1 || firstParticle.size() != current.back() + 1) return false;
  const double now = predictedStep(m_cost, current, firstParticle);
  const double best = predictedStep(m_cost, edges(m_threads, firstParticle), firstParticle);
  return best < (1.0 - kMinGain) * now;
}

}  // namespace fl
