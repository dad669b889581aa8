#include "measurements.hpp"

#include <cmath>

#include <Eigen/Eigenvalues>

namespace fl {

StressMeasures stressMeasures(const Mat3& sigma) {
  StressMeasures m;
  m.tensor = sigma;
  m.p = sigma.trace() / 3.0;
  m.axial = sigma(2, 2);
  m.lateral = 0.5 * (sigma(0, 0) + sigma(1, 1));
  m.q = m.axial - m.lateral;
  m.tau = 0.5 * m.q;
  return m;
}

StrainMeasures strainMeasures(const PeriodicCell& cell, const Mat3& reference) {
  StrainMeasures s;
  for (int k = 0; k < 3; ++k) s.principal[k] = -std::log(cell.matrix()(k, k) / reference(k, k));
  s.axial = s.principal.z();
  s.radial = 0.5 * (s.principal.x() + s.principal.y());
  s.volumetric = s.principal.sum();
  s.shear = s.axial - s.radial;
  return s;
}

ContactCounts contactCounts(const Simulation& sim) {
  const ContactStore& c = sim.contacts();
  const std::size_t n = sim.particles().size();
  ContactCounts r;
  std::vector<int> per(n, 0);
  for (std::size_t p = 0; p < c.size(); ++p)
    if (c.active(p)) {
      ++r.contacts;
      ++per[c.first[p]];
      ++per[c.second[p]];
    }
  for (int k : per) {
    r.rattlers0 += k == 0;
    r.rattlers1 += k == 1;
  }
  r.coordination = n ? 2.0 * r.contacts / n : 0.0;
  const double denom = static_cast<double>(n) - r.rattlers0 - r.rattlers1;
  r.mechanicalCoordination = denom > 0 ? (2.0 * r.contacts - r.rattlers1) / denom : 0.0;
  return r;
}

namespace {
template <class ForEachNormal>
FabricMeasures fabricImpl(ForEachNormal&& each) {
  FabricMeasures f;
  Mat3 phi = Mat3::Zero();
  Eigen::Matrix2d xz = Eigen::Matrix2d::Zero(), yz = Eigen::Matrix2d::Zero();
  std::size_t nxz = 0, nyz = 0;
  each([&](const Vec3& n) {
    phi += n * n.transpose();
    ++f.contacts;
    // projections on the vertical planes, renormalised to unit 2D vectors
    const Eigen::Vector2d a(n.x(), n.z()), b(n.y(), n.z());
    if (a.squaredNorm() > 1e-24) {
      xz += a.normalized() * a.normalized().transpose();
      ++nxz;
    }
    if (b.squaredNorm() > 1e-24) {
      yz += b.normalized() * b.normalized().transpose();
      ++nyz;
    }
  });
  if (f.contacts == 0) return f;
  f.tensor = phi / static_cast<double>(f.contacts);
  f.deviator = f.tensor - Mat3::Identity() / 3.0;
  f.anisotropy3D = 2.5 * (f.tensor(2, 2) - 0.5 * (f.tensor(0, 0) + f.tensor(1, 1)));
  double a2 = 0.0, dir = 0.0;
  int planes = 0;
  for (auto [m, cnt] : {std::pair{xz, nxz}, std::pair{yz, nyz}}) {
    if (cnt == 0) continue;
    const Eigen::Matrix2d t = m / static_cast<double>(cnt);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(t);
    a2 += 2.0 * (es.eigenvalues()(1) - es.eigenvalues()(0));
    const Eigen::Vector2d major = es.eigenvectors().col(1);
    dir += std::acos(std::min(1.0, std::abs(major.y())));  // angle of the major direction from vertical
    ++planes;
  }
  if (planes) {
    f.anisotropy2D = a2 / planes;
    f.direction2D = dir / planes;
  }
  return f;
}
}  // namespace

FabricMeasures fabricMeasures(const Simulation& sim) {
  const ContactStore& c = sim.contacts();
  return fabricImpl([&](auto&& use) {
    for (std::size_t p = 0; p < c.size(); ++p)
      if (c.active(p)) use(c.normal(p, sim.particles(), sim.cell()));
  });
}

FabricMeasures fabricFromNormals(const std::vector<Vec3>& normals) {
  return fabricImpl([&](auto&& use) {
    for (const Vec3& n : normals) use(n);
  });
}

double voidRatio(const Simulation& sim) {
  const double vs = sim.particles().solidVolume();
  return (sim.cell().volume() - vs) / vs;
}

double meanDiameter(const ParticleStore& p) {
  double d = 0.0;
  for (double r : p.radius) d += 2.0 * r;
  return p.size() ? d / static_cast<double>(p.size()) : 0.0;
}

double inertialNumber(const Simulation& sim, double meanPressure) {
  if (meanPressure <= 0.0) return 0.0;
  const Mat3& L = sim.cell().velocityGradient();
  const double rate = L.diagonal().cwiseAbs().maxCoeff();
  const double rho = sim.materials()[0].density * sim.numerics().densityScale;
  return rate * meanDiameter(sim.particles()) * std::sqrt(rho / meanPressure);
}

}  // namespace fl
