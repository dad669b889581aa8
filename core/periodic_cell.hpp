// The periodic deformable cell (after YADE's Cell and HOOMD's BoxDim).
//   H: cell matrix, columns are the three cell vectors [m]; a point x has reduced coordinates s = H^-1 x.
//   L: imposed velocity gradient [1/s]; the homogeneous velocity field is L·x and the cell evolves as
//      dH/dt = L·H. Particle velocities are stored relative to that field.
//   An image of particle j shifted by the integer vector n sits at x_j + H·n and moves with the extra
//   velocity L·H·n (the "shift velocity"), which the contact kinematics must include.
// Validity: general (triclinic) H and L are supported by the maths; the neighbour grid requires each
// perpendicular width of the cell to exceed the interaction cut-off (checked, CellTooSmallError).
// Time update: while L stays diagonal the logarithmic strain e_k += L_kk dt is accumulated and
// H = diag(exp(e)) H_ref is formed from it, so an isochoric L (trace 0) keeps det H to round-off over
// any number of steps (multiplying by a fixed exp(L dt) would drift by its rounding every step; the sum
// itself is Kahan-compensated for the same reason). A
// general L uses a second-order Taylor step and resets the reference.
#pragma once

#include "types.hpp"

namespace fl {

class PeriodicCell {
 public:
  PeriodicCell() : PeriodicCell(Mat3::Identity()) {}
  explicit PeriodicCell(const Mat3& H) { setMatrix(H); }
  static PeriodicCell box(double lx, double ly, double lz) {
    return PeriodicCell(Vec3(lx, ly, lz).asDiagonal().toDenseMatrix());
  }

  const Mat3& matrix() const { return m_H; }
  const Mat3& inverse() const { return m_Hinv; }
  const Mat3& velocityGradient() const { return m_L; }
  void setVelocityGradient(const Mat3& L) { m_L = L; }
  void setMatrix(const Mat3& H);  // also restarts the log-strain reference

  double volume() const { return m_H.determinant(); }
  Vec3 shift(const Vec3i& n) const { return m_H * n.cast<double>(); }                 // H·n [m]
  Vec3 shiftVelocity(const Vec3i& n) const { return m_L * (m_H * n.cast<double>()); }  // L·H·n [m/s]
  Vec3 reduced(const Vec3& x) const { return m_Hinv * x; }
  // Distance between opposite faces for each cell vector: 1/|row_k(H^-1)| [m].
  Vec3 perpendicularWidths() const;
  // Wrap x into the cell; returns the integer vector k with x_new = x - H·k.
  Vec3i wrap(Vec3& x) const;
  // checkpoint support: the log-strain accumulation state
  const Mat3& logStrainReference() const { return m_Href; }
  const Vec3& logStrain() const { return m_logStrain; }
  const Vec3& logStrainCompensation() const { return m_logComp; }
  void restore(const Mat3& H, const Mat3& L, const Mat3& Href, const Vec3& logStrain, const Vec3& comp) {
    setMatrix(H);
    m_L = L;
    m_Href = Href;
    m_logStrain = logStrain;
    m_logComp = comp;
  }
  // Advance H by dt under the current L; returns the affine map Phi with H_new = Phi·H_old
  // (particles follow x_new = Phi·x_old + dt·v').
  Mat3 advance(double dt);

 private:
  Mat3 m_H;
  Mat3 m_Hinv;
  Mat3 m_L = Mat3::Zero();
  Mat3 m_Href;                    // H when the log-strain accumulation started
  Vec3 m_logStrain = Vec3::Zero();  // accumulated L_kk dt since m_Href [-]
  Vec3 m_logComp = Vec3::Zero();    // Kahan compensation of that sum: small constant increments added to
                                    // a large total would otherwise round the same way every step
};

}  // namespace fl
