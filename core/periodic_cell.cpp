#include "periodic_cell.hpp"

#include <cmath>

#include <Eigen/LU>

#include "errors.hpp"

namespace fl {

void PeriodicCell::setMatrix(const Mat3& H) {
  if (!(H.determinant() > 0.0)) throw InputError("periodic cell: matrix must have a positive determinant");
  m_H = H;
  m_Hinv = H.inverse();
  m_Href = H;
  m_logStrain.setZero();
  m_logComp.setZero();
}

Vec3 PeriodicCell::perpendicularWidths() const {
  return Vec3(1.0 / m_Hinv.row(0).norm(), 1.0 / m_Hinv.row(1).norm(), 1.0 / m_Hinv.row(2).norm());
}

Vec3i PeriodicCell::wrap(Vec3& x) const {
  const Vec3 s = m_Hinv * x;
  const Vec3i k(static_cast<int>(std::floor(s.x())), static_cast<int>(std::floor(s.y())),
                static_cast<int>(std::floor(s.z())));
  if (k != Vec3i::Zero()) x -= m_H * k.cast<double>();
  return k;
}

Mat3 PeriodicCell::advance(double dt) {
  if (m_L.isZero(0.0)) return Mat3::Identity();
  const bool diagonal = m_L(0, 1) == 0.0 && m_L(0, 2) == 0.0 && m_L(1, 0) == 0.0 && m_L(1, 2) == 0.0 &&
                        m_L(2, 0) == 0.0 && m_L(2, 1) == 0.0;
  if (diagonal) {
    const Vec3 old = m_logStrain;
    for (int a = 0; a < 3; ++a) {  // Kahan summation
      const double y = m_L(a, a) * dt - m_logComp[a];
      const double t = m_logStrain[a] + y;
      m_logComp[a] = (t - m_logStrain[a]) - y;
      m_logStrain[a] = t;
    }
    Mat3 phi = Mat3::Zero();
    Mat3 H = m_Href;
    for (int a = 0; a < 3; ++a) {
      phi(a, a) = std::exp(m_logStrain[a] - old[a]);
      H.row(a) *= std::exp(m_logStrain[a]);
    }
    m_H = H;
    m_Hinv = H.inverse();
    return phi;
  }
  const Mat3 Ld = m_L * dt;
  const Mat3 phi = Mat3::Identity() + Ld + 0.5 * Ld * Ld;
  setMatrix(phi * m_H);
  return phi;
}

}  // namespace fl
