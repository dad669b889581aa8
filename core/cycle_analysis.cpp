#include "cycle_analysis.hpp"

#include <algorithm>
#include <cmath>

#include "types.hpp"

namespace fl {

CycleRecord CycleAnalyzer::close(int cycle, const CycleEndState& end) {
  CycleRecord r;
  r.cycle = cycle;
  r.end = end;
  if (m_points.empty()) return r;
  const CyclePoint& f = m_points.front();
  r.tauMin = r.tauMax = f.tau;
  r.pMin = r.pMax = f.p;
  r.duMin = r.duMax = f.du;
  r.gammaMin = r.gammaMax = f.gamma;
  double qMin = f.q, qMax = f.q, eMin = f.epsA, eMax = f.epsA, area = 0.0;
  for (std::size_t k = 0; k < m_points.size(); ++k) {
    const CyclePoint& c = m_points[k];
    r.tauMin = std::min(r.tauMin, c.tau);
    r.tauMax = std::max(r.tauMax, c.tau);
    r.pMin = std::min(r.pMin, c.p);
    r.pMax = std::max(r.pMax, c.p);
    r.duMin = std::min(r.duMin, c.du);
    r.duMax = std::max(r.duMax, c.du);
    r.gammaMin = std::min(r.gammaMin, c.gamma);
    r.gammaMax = std::max(r.gammaMax, c.gamma);
    qMin = std::min(qMin, c.q);
    qMax = std::max(qMax, c.q);
    eMin = std::min(eMin, c.epsA);
    eMax = std::max(eMax, c.epsA);
    if (k > 0) {
      const CyclePoint& b = m_points[k - 1];
      area += 0.5 * (c.tau + b.tau) * (c.gamma - b.gamma);
    }
  }
  r.duEnd = m_points.back().du;
  const double dg = r.gammaMax - r.gammaMin;
  r.Gsec = dg > 0 ? (r.tauMax - r.tauMin) / dg : 0.0;
  r.Esec = eMax > eMin ? (qMax - qMin) / (eMax - eMin) : 0.0;
  const double wel = r.Gsec * dg * dg / 8.0;
  r.damping = wel > 0 ? std::abs(area) / (4.0 * kPi * wel) : 0.0;
  if (cycle == 1) m_G1 = r.Gsec;
  r.failed = (m_p0 > 0 && r.pMin < m_failure.minPressureFraction * m_p0) ||
             (m_G1 > 0 && r.Gsec < m_failure.minStiffnessFraction * m_G1);
  const CyclePoint last = m_points.back();
  m_points.clear();
  m_points.push_back(last);
  return r;
}

}  // namespace fl
