// Per-cycle analysis of strain-controlled cyclic loading (the paper's Figures 3, 4, 6, 8, 9):
//   G_sec = (tau_max - tau_min) / (gamma_max - gamma_min)   (the paper's secant shear stiffness)
//   E_sec = (q_max - q_min) / (eps_a,max - eps_a,min)
//   damping ratio D = W_loop / (4 pi W_el), W_loop = |closed integral tau d gamma| (trapezoids),
//                     W_el = G_sec (gamma_max - gamma_min)^2 / 8
// plus the ranges of tau, p', Delta u, and eps_v, Z, Zm, a at the end of the cycle.
// Failure flag (documented criterion): a cycle fails when its minimum p' falls below
// minPressureFraction x p'_0 (p'_0 at the start of cycling: liquefaction / cyclic mobility) or its G_sec
// falls below minStiffnessFraction x G_sec of cycle 1. The first failed cycle is the failure cycle.
#pragma once

#include <vector>

namespace fl {

struct FailureCriteria {
  double minPressureFraction = 0.2;   // [-]
  double minStiffnessFraction = 0.2;  // [-]
};

struct CyclePoint {
  double gamma = 0, tau = 0, epsA = 0, q = 0, p = 0, du = 0;
};

struct CycleEndState {
  double epsV = 0, Z = 0, Zm = 0, a3D = 0, a2D = 0, voidRatio = 0;
};

struct CycleRecord {
  int cycle = 0;  // 1-based
  double Gsec = 0, Esec = 0, damping = 0;           // [Pa], [Pa], [-]
  double tauMin = 0, tauMax = 0, pMin = 0, pMax = 0;  // [Pa]
  double duMin = 0, duMax = 0, duEnd = 0;             // [Pa]
  double gammaMin = 0, gammaMax = 0;                  // [-]
  CycleEndState end;
  bool failed = false;
};

class CycleAnalyzer {
 public:
  CycleAnalyzer() = default;
  CycleAnalyzer(double p0, FailureCriteria f) : m_p0(p0), m_failure(f) {}
  void add(const CyclePoint& pt) { m_points.push_back(pt); }
  // Closes the current cycle: computes its record and starts the next one from the last point.
  CycleRecord close(int cycle, const CycleEndState& end);
  std::size_t pointCount() const { return m_points.size(); }
  double firstStiffness() const { return m_G1; }
  // checkpoint support
  const std::vector<CyclePoint>& points() const { return m_points; }
  void restore(double p0, double G1, FailureCriteria f, std::vector<CyclePoint> pts) {
    m_p0 = p0;
    m_G1 = G1;
    m_failure = f;
    m_points = std::move(pts);
  }
  double initialPressure() const { return m_p0; }
  const FailureCriteria& failure() const { return m_failure; }

 private:
  double m_p0 = 0.0, m_G1 = 0.0;
  FailureCriteria m_failure;
  std::vector<CyclePoint> m_points;
};

}  // namespace fl
