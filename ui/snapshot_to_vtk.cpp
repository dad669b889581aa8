#include "ui/snapshot_to_vtk.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkSphereSource.h>

namespace fl::ui {

namespace {

vtkSmartPointer<vtkDoubleArray> namedArray(const char* name, vtkIdType tuples = 0) {
  auto a = vtkSmartPointer<vtkDoubleArray>::New();
  a->SetName(name);
  a->SetNumberOfComponents(1);
  if (tuples > 0) a->SetNumberOfTuples(tuples);
  return a;
}

Eigen::Vector2d project(const Vec3& n, RosePlane plane) {
  switch (plane) {
    case RosePlane::XZ: return {n.x(), n.z()};
    case RosePlane::YZ: return {n.y(), n.z()};
    case RosePlane::XY: return {n.x(), n.y()};
  }
  return {n.x(), n.z()};
}

double weightOf(const std::vector<double>& w, std::size_t i) { return w.empty() ? 1.0 : w[i]; }

}  // namespace

const char* colorFieldName(ColorField f) {
  switch (f) {
    case ColorField::Size: return "radius [m]";
    case ColorField::Speed: return "speed |v'| [m/s]";
    case ColorField::ContactCount: return "contacts per particle";
    case ColorField::MeanStress: return "particle mean stress p_p [Pa]";
  }
  return "?";
}

std::vector<double> particleField(const Snapshot& s, ColorField f) {
  switch (f) {
    case ColorField::Size: return s.radii;
    case ColorField::Speed: return s.speeds;
    case ColorField::ContactCount: return {s.contactCounts.begin(), s.contactCounts.end()};
    case ColorField::MeanStress: return s.meanStress;
  }
  return s.radii;
}

vtkSmartPointer<vtkPolyData> particlesPolyData(const Snapshot& s, ColorField f, bool periodicImages) {
  const std::vector<double> field = particleField(s, f);
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetDataTypeToDouble();
  auto radius = namedArray("radius");
  auto value = namedArray("field");
  points->Allocate(static_cast<vtkIdType>(s.positions.size()));
  const Mat3 Hinv = s.cell.inverse();
  // perpendicular widths 1/|row_k(H^-1)| turn a radius into a reduced-coordinate margin per axis
  const Vec3 widths(1.0 / Hinv.row(0).norm(), 1.0 / Hinv.row(1).norm(), 1.0 / Hinv.row(2).norm());
  for (std::size_t i = 0; i < s.positions.size(); ++i) {
    const Vec3& x = s.positions[i];
    const double r = i < s.radii.size() ? s.radii[i] : 0.0;
    const double v = i < field.size() ? field[i] : 0.0;
    points->InsertNextPoint(x.x(), x.y(), x.z());
    radius->InsertNextValue(r);
    value->InsertNextValue(v);
    if (!periodicImages) continue;
    const Vec3 red = Hinv * x;
    int shift[3][2];  // per axis: candidate shifts {0, +-1}
    int count[3];
    for (int k = 0; k < 3; ++k) {
      const double margin = r / widths[k];
      count[k] = 1;
      shift[k][0] = 0;
      if (red[k] < margin) shift[k][count[k]++] = 1;
      else if (red[k] > 1.0 - margin) shift[k][count[k]++] = -1;
    }
    for (int a = 0; a < count[0]; ++a)
      for (int b = 0; b < count[1]; ++b)
        for (int c = 0; c < count[2]; ++c) {
          if (a == 0 && b == 0 && c == 0) continue;
          const Vec3 y = x + s.cell * Vec3(shift[0][a], shift[1][b], shift[2][c]);
          points->InsertNextPoint(y.x(), y.y(), y.z());
          radius->InsertNextValue(r);
          value->InsertNextValue(v);
        }
  }
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(points);
  poly->GetPointData()->AddArray(radius);
  poly->GetPointData()->AddArray(value);
  poly->GetPointData()->SetActiveScalars("field");
  return poly;
}

vtkSmartPointer<vtkPolyData> forceChainPolyData(const Snapshot& s, double threshold, double upper) {
  double maxForce = 0.0, meanRadius = 0.0;
  for (const auto& c : s.contacts) maxForce = std::max(maxForce, c.normalForce);
  for (double r : s.radii) meanRadius += r;
  if (!s.radii.empty()) meanRadius /= static_cast<double>(s.radii.size());

  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetDataTypeToDouble();
  auto lines = vtkSmartPointer<vtkCellArray>::New();
  auto pointForce = namedArray("normal_force");
  auto cellForce = namedArray("normal_force");
  auto tube = namedArray("tube_radius");
  for (const auto& c : s.contacts) {
    if (!(c.normalForce > threshold) || c.normalForce > upper) continue;
    const Vec3 a = c.start, b = c.start + c.branch;
    const vtkIdType ids[2] = {points->InsertNextPoint(a.x(), a.y(), a.z()), points->InsertNextPoint(b.x(), b.y(), b.z())};
    lines->InsertNextCell(2, ids);
    // Width grows linearly with the force, from a thin 5 % of the mean radius to 45 % at the strongest.
    const double t = maxForce > 0 ? c.normalForce / maxForce : 0.0;
    const double w = meanRadius * (0.05 + 0.4 * t);
    for (int k = 0; k < 2; ++k) {
      pointForce->InsertNextValue(c.normalForce);
      tube->InsertNextValue(w);
    }
    cellForce->InsertNextValue(c.normalForce);
  }
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(points);
  poly->SetLines(lines);
  poly->GetPointData()->AddArray(pointForce);
  poly->GetPointData()->AddArray(tube);
  poly->GetPointData()->SetActiveScalars("tube_radius");
  poly->GetCellData()->AddArray(cellForce);
  return poly;
}

vtkSmartPointer<vtkPolyData> cellBoxPolyData(const Mat3& H) {
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetDataTypeToDouble();
  for (int k = 0; k < 8; ++k) {
    const Vec3 s((k & 1) ? 1.0 : 0.0, (k & 2) ? 1.0 : 0.0, (k & 4) ? 1.0 : 0.0);
    const Vec3 x = H * s;
    points->InsertNextPoint(x.x(), x.y(), x.z());
  }
  auto lines = vtkSmartPointer<vtkCellArray>::New();
  for (int k = 0; k < 8; ++k)
    for (int bit : {1, 2, 4})
      if (!(k & bit)) {
        const vtkIdType ids[2] = {k, k | bit};
        lines->InsertNextCell(2, ids);
      }
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(points);
  poly->SetLines(lines);
  return poly;
}

const char* rosePlaneName(RosePlane p) {
  switch (p) {
    case RosePlane::XZ: return "x-z (vertical)";
    case RosePlane::YZ: return "y-z (vertical)";
    case RosePlane::XY: return "x-y (horizontal)";
  }
  return "?";
}

RoseHistogram roseHistogram(const std::vector<Vec3>& normals, const std::vector<double>& weights, RosePlane plane,
                            int bins) {
  RoseHistogram h;
  h.plane = plane;
  bins = std::max(bins, 4);
  h.density.assign(static_cast<std::size_t>(bins), 0.0);
  double a = 0, b = 0, d = 0, total = 0;  // 2D fabric [[a, b], [b, d]]
  const double binWidth = 2.0 * kPi / bins;
  for (std::size_t i = 0; i < normals.size(); ++i) {
    Eigen::Vector2d m = project(normals[i], plane);
    if (m.squaredNorm() < 1e-24) continue;
    m.normalize();
    const double w = weightOf(weights, i);
    for (int sign : {1, -1}) {  // n and -n
      double theta = std::atan2(sign * m.y(), sign * m.x());
      if (theta < 0) theta += 2.0 * kPi;
      const int k = std::min(bins - 1, static_cast<int>(theta / binWidth));
      h.density[static_cast<std::size_t>(k)] += w;
    }
    a += w * m.x() * m.x();
    b += w * m.x() * m.y();
    d += w * m.y() * m.y();
    total += w;
    ++h.contacts;
  }
  if (total > 0) {
    // normalise so that a uniform distribution gives 1 in every bin: each normal was counted twice
    for (double& v : h.density) v *= bins / (2.0 * total);
    a /= total;
    b /= total;
    d /= total;
    const double half = 0.5 * (a - d);
    const double root = std::sqrt(half * half + b * b);
    h.anisotropy = 2.0 * (2.0 * root);  // lambda1 - lambda2 = 2 root; a = 2 (lambda1 - lambda2)
    h.direction = 0.5 * std::atan2(2.0 * b, a - d);
  }
  return h;
}

vtkSmartPointer<vtkPolyData> rosePolyData(const RoseHistogram& h) {
  auto points = vtkSmartPointer<vtkPoints>::New();
  auto polys = vtkSmartPointer<vtkCellArray>::New();
  auto density = namedArray("density");
  const int bins = static_cast<int>(h.density.size());
  const vtkIdType origin = points->InsertNextPoint(0, 0, 0);
  for (int k = 0; k < bins; ++k) {
    const double r = h.density[static_cast<std::size_t>(k)];
    vtkIdType ids[4] = {origin, 0, 0, 0};
    for (int j = 0; j < 3; ++j) {  // start, middle and end of the arc
      const double t = 2.0 * kPi * (k + 0.5 * j) / bins;
      ids[j + 1] = points->InsertNextPoint(r * std::cos(t), r * std::sin(t), 0.0);
    }
    polys->InsertNextCell(4, ids);
    density->InsertNextValue(r);
  }
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(points);
  poly->SetPolys(polys);
  poly->GetCellData()->AddArray(density);
  poly->GetCellData()->SetActiveScalars("density");
  return poly;
}

vtkSmartPointer<vtkPolyData> roseGuidesPolyData(const RoseHistogram& h) {
  auto points = vtkSmartPointer<vtkPoints>::New();
  auto lines = vtkSmartPointer<vtkCellArray>::New();
  constexpr int kCircle = 72;
  std::vector<vtkIdType> circle;
  for (int k = 0; k <= kCircle; ++k) {
    const double t = 2.0 * kPi * k / kCircle;
    circle.push_back(points->InsertNextPoint(std::cos(t), std::sin(t), 0.0));
  }
  lines->InsertNextCell(static_cast<vtkIdType>(circle.size()), circle.data());
  // principal directions through the origin: major 1 + a/2, minor 1 - a/2 (the R–B rose's extremes)
  for (int k = 0; k < 2; ++k) {
    const double t = h.direction + k * 0.5 * kPi;
    const double len = k == 0 ? 1.0 + 0.5 * h.anisotropy : std::max(0.0, 1.0 - 0.5 * h.anisotropy);
    const vtkIdType ids[2] = {points->InsertNextPoint(-len * std::cos(t), -len * std::sin(t), 0.0),
                              points->InsertNextPoint(len * std::cos(t), len * std::sin(t), 0.0)};
    lines->InsertNextCell(2, ids);
  }
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(points);
  poly->SetLines(lines);
  return poly;
}

Mat3 weightedFabric(const std::vector<Vec3>& normals, const std::vector<double>& weights) {
  Mat3 phi = Mat3::Zero();
  double total = 0;
  for (std::size_t i = 0; i < normals.size(); ++i) {
    const double w = weightOf(weights, i);
    phi += w * normals[i] * normals[i].transpose();
    total += w;
  }
  return total > 0 ? Mat3(phi / total) : Mat3(Mat3::Identity() / 3.0);
}

SphericalRose sphericalRose(const std::vector<Vec3>& normals, const std::vector<double>& weights, int resolution,
                            double coneDegrees) {
  vtkNew<vtkSphereSource> sphere;
  sphere->SetRadius(1.0);
  sphere->SetThetaResolution(2 * std::max(resolution, 4));
  sphere->SetPhiResolution(std::max(resolution, 4));
  sphere->Update();
  SphericalRose out;
  out.surface = vtkSmartPointer<vtkPolyData>::New();
  out.surface->DeepCopy(sphere->GetOutput());
  out.surface->GetPointData()->Initialize();  // drop the source's normals: the shape changes

  const double cosCone = std::cos(coneDegrees * kPi / 180.0);
  double total = 0;
  for (std::size_t i = 0; i < normals.size(); ++i) total += weightOf(weights, i);
  vtkPoints* pts = out.surface->GetPoints();
  auto density = namedArray("density", pts->GetNumberOfPoints());
  out.minDensity = 1e300;
  out.maxDensity = 0;
  for (vtkIdType p = 0; p < pts->GetNumberOfPoints(); ++p) {
    double x[3];
    pts->GetPoint(p, x);
    const Vec3 dir = Vec3(x[0], x[1], x[2]).normalized();
    double inCone = 0;
    for (std::size_t i = 0; i < normals.size(); ++i)
      if (std::abs(dir.dot(normals[i])) >= cosCone) inCone += weightOf(weights, i);
    // fraction of the 2N directions (n and -n) inside the cone over the cone's solid-angle fraction
    const double rho = total > 0 ? inCone / (total * (1.0 - cosCone)) : 0.0;
    density->SetValue(p, rho);
    pts->SetPoint(p, rho * dir.x(), rho * dir.y(), rho * dir.z());
    out.minDensity = std::min(out.minDensity, rho);
    out.maxDensity = std::max(out.maxDensity, rho);
  }
  if (pts->GetNumberOfPoints() == 0) out.minDensity = 0;
  out.surface->GetPointData()->AddArray(density);
  out.surface->GetPointData()->SetActiveScalars("density");

  // principal directions of the weighted fabric, drawn as +-3 lambda_k (isotropic: length 1)
  Eigen::SelfAdjointEigenSolver<Mat3> eig(weightedFabric(normals, weights));
  auto apts = vtkSmartPointer<vtkPoints>::New();
  auto lines = vtkSmartPointer<vtkCellArray>::New();
  auto lambda = namedArray("eigenvalue");
  for (int k = 0; k < 3; ++k) {
    const Vec3 v = 3.0 * eig.eigenvalues()[k] * eig.eigenvectors().col(k) * 1.3;
    const vtkIdType ids[2] = {apts->InsertNextPoint(-v.x(), -v.y(), -v.z()), apts->InsertNextPoint(v.x(), v.y(), v.z())};
    lines->InsertNextCell(2, ids);
    lambda->InsertNextValue(eig.eigenvalues()[k]);
  }
  out.axes = vtkSmartPointer<vtkPolyData>::New();
  out.axes->SetPoints(apts);
  out.axes->SetLines(lines);
  out.axes->GetCellData()->AddArray(lambda);
  return out;
}

}  // namespace fl::ui
