// Measures of the state, computed from stored data (particles, cell, contact store): never re-runs the
// force law. Conventions: compression positive; the axial (vertical) direction is z (index 2), the lateral
// ones x and y; strains are logarithmic (natural) and measured from a reference cell matrix, so that a
// constant-volume path has eps_v = 0 to round-off however large the strain.
//   p' = tr(sigma)/3, q = sigma_zz - (sigma_xx + sigma_yy)/2, tau = q/2,
//   eps_a = eps_zz, eps_r = (eps_xx + eps_yy)/2, eps_v = tr(eps), gamma = eps_a - eps_r (= eps_1 - eps_3).
// Fabric: phi_ij = (1/C) sum n_i n_j over touching contacts (trace 1). Two anisotropy measures, labelled:
//   a_3D  = (5/2)(phi_zz - (phi_xx + phi_yy)/2), exact for E(n) = (1/4pi)[1 + a(3cos^2 theta - 1)];
//   a_2D  = 2(lambda1 - lambda2) of the 2D fabric of normals projected on the vertical planes x-z and y-z
//           (averaged), the Rothenburg & Bathurst (1989) form E(theta) = (1/2pi)[1 + a cos 2(theta - theta_a)]
//           used by the paper (a = 0.018 isotropic, 0.213 anisotropic specimen).
// Coordination: Z = 2C/N; mechanical Zm = (2C - N1)/(N - N0 - N1) (Thornton 2000), N0/N1 the particles
// with zero/one contact.
#pragma once

#include "simulation.hpp"

namespace fl {

struct StressMeasures {
  Mat3 tensor = Mat3::Zero();  // contact (Love–Weber) stress [Pa]
  double p = 0.0, q = 0.0, tau = 0.0;  // [Pa]
  double axial = 0.0, lateral = 0.0;   // sigma_zz, (sigma_xx + sigma_yy)/2 [Pa]
};
StressMeasures stressMeasures(const Mat3& sigma);

struct StrainMeasures {
  Vec3 principal = Vec3::Zero();  // eps_xx, eps_yy, eps_zz [-]
  double axial = 0.0, radial = 0.0, volumetric = 0.0, shear = 0.0;  // eps_a, eps_r, eps_v, gamma [-]
};
// Orthorhombic cells: eps_kk = -ln(H_kk / Href_kk).
StrainMeasures strainMeasures(const PeriodicCell& cell, const Mat3& reference);

struct ContactCounts {
  std::size_t contacts = 0;  // C
  std::size_t rattlers0 = 0, rattlers1 = 0;  // N0, N1
  double coordination = 0.0;        // Z
  double mechanicalCoordination = 0.0;  // Zm
};
ContactCounts contactCounts(const Simulation& sim);

struct FabricMeasures {
  Mat3 tensor = Mat3::Zero();     // phi
  Mat3 deviator = Mat3::Zero();   // phi - I/3
  double anisotropy3D = 0.0;      // a_3D (see header)
  double anisotropy2D = 0.0;      // a_2D, Rothenburg–Bathurst on vertical planes
  double direction2D = 0.0;       // theta_a from the vertical in the projected fabric, [0, pi/2] [rad]
  std::size_t contacts = 0;
};
FabricMeasures fabricMeasures(const Simulation& sim);  // of the touching pairs' normals
// The same for an explicit list of unit normals (used by tests and rose diagrams).
FabricMeasures fabricFromNormals(const std::vector<Vec3>& normals);

double voidRatio(const Simulation& sim);  // (V - Vs)/Vs, overlaps neglected [-]
// I = eps_dot d_mean sqrt(rho / p'), eps_dot the largest |L_kk| [-]; 0 when p' <= 0.
double inertialNumber(const Simulation& sim, double meanPressure);
double meanDiameter(const ParticleStore& p);

}  // namespace fl
