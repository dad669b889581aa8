// Snapshot creation and Snapshot -> VTK conversions, without any window (house-style §15), plus the plot
// decimation. Runs without a display.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <random>

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkPointData.h>

#include "core/measurements.hpp"
#include "core/scene.hpp"
#include "ui/decimate.hpp"
#include "ui/snapshot.hpp"
#include "ui/snapshot_to_vtk.hpp"
#include "ui_test_support.hpp"

using namespace fl;
using namespace fl::ui;

namespace {

std::vector<Vec3> randomNormals(int n, unsigned seed, double stretchZ = 1.0) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Vec3> out;
  for (int i = 0; i < n; ++i) {
    Vec3 v(g(rng), g(rng), stretchZ * g(rng));
    out.push_back(v.normalized());
  }
  return out;
}

// Three particles in a 10 mm box, two contacts with known forces.
Snapshot handMade() {
  Snapshot s;
  s.cell = Vec3(0.01, 0.01, 0.01).asDiagonal();
  s.positions = {Vec3(0.005, 0.005, 0.005), Vec3(0.005, 0.005, 0.006), Vec3(0.0003, 0.005, 0.005)};
  s.radii = {0.0005, 0.0005, 0.0005};
  s.speeds = {0.0, 1.0, 2.0};
  s.contactCounts = {2, 1, 1};
  s.meanStress = {10.0, 5.0, 5.0};
  s.contacts.push_back({0, 1, s.positions[0], Vec3(0, 0, 0.00099), 3.0});
  s.contacts.push_back({0, 2, s.positions[0], Vec3(-0.00099, 0, 0), 1.0});
  return s;
}

}  // namespace

TEST(UiSnapshot, FromRunnerCopiesParticlesAndTouchingContacts) {
  Runner runner(parseScene(nlohmann::json::parse(test::tinySceneJson(), nullptr, true, true), "tiny"));
  runner.advance(3000);
  RunStatus st;
  st.state = RunState::Paused;
  const Snapshot s = makeSnapshot(runner, st);
  const auto& sim = runner.simulation();
  ASSERT_EQ(s.positions.size(), sim.particles().size());
  EXPECT_EQ(s.radii.size(), s.positions.size());
  EXPECT_EQ(s.contacts.size(), sim.contacts().activeCount());
  long sum = 0;
  for (int c : s.contactCounts) sum += c;
  EXPECT_EQ(sum, 2 * static_cast<long>(s.contacts.size()));
  // wrapped into the cell
  const Mat3 Hinv = s.cell.inverse();
  for (const auto& x : s.positions) {
    const Vec3 r = Hinv * x;
    EXPECT_GE(r.minCoeff(), -1e-12);
    EXPECT_LT(r.maxCoeff(), 1.0 + 1e-12);
  }
  for (double p : s.meanStress) EXPECT_GE(p, 0.0);
  for (const auto& c : s.contacts) {
    EXPECT_GT(c.normalForce, 0.0);
    const double reach = s.radii[c.first] + s.radii[c.second];
    EXPECT_LT(c.branch.norm(), reach);  // touching: closer than the sum of radii
  }
  ASSERT_TRUE(s.samples);
  EXPECT_EQ(s.samples->size(), runner.samples().size());
  // an unchanged time series is shared, not copied
  const Snapshot again = makeSnapshot(runner, st, &s);
  EXPECT_EQ(again.samples.get(), s.samples.get());
  EXPECT_EQ(again.serial, s.serial + 1);
}

TEST(UiSnapshotToVtk, ParticlesCarryRadiusAndFieldRange) {
  const Snapshot s = handMade();
  auto poly = particlesPolyData(s, ColorField::Speed);
  ASSERT_EQ(poly->GetNumberOfPoints(), 3);
  double range[2];
  poly->GetPointData()->GetArray("field")->GetRange(range);
  EXPECT_DOUBLE_EQ(range[0], 0.0);
  EXPECT_DOUBLE_EQ(range[1], 2.0);
  poly->GetPointData()->GetArray("radius")->GetRange(range);
  EXPECT_DOUBLE_EQ(range[1], 0.0005);
  auto counts = particlesPolyData(s, ColorField::ContactCount);
  counts->GetPointData()->GetArray("field")->GetRange(range);
  EXPECT_DOUBLE_EQ(range[0], 1.0);
  EXPECT_DOUBLE_EQ(range[1], 2.0);
}

TEST(UiSnapshotToVtk, PeriodicImagesRepeatParticlesCutByAFace) {
  const Snapshot s = handMade();
  // particle 2 sits 0.3 mm from the x = 0 face with r = 0.5 mm: one image across x
  auto poly = particlesPolyData(s, ColorField::Size, true);
  EXPECT_EQ(poly->GetNumberOfPoints(), 4);
  double x[3];
  poly->GetPoint(3, x);
  EXPECT_NEAR(x[0], 0.0103, 1e-12);
}

TEST(UiSnapshotToVtk, ForceChainsFilterByThreshold) {
  const Snapshot s = handMade();
  EXPECT_DOUBLE_EQ(s.meanNormalForce(), 2.0);
  auto all = forceChainPolyData(s, 0.0);
  EXPECT_EQ(all->GetNumberOfLines(), 2);
  EXPECT_EQ(all->GetNumberOfPoints(), 4);
  auto strong = forceChainPolyData(s, s.meanNormalForce());  // default: above the mean
  ASSERT_EQ(strong->GetNumberOfLines(), 1);
  double range[2];
  strong->GetCellData()->GetArray("normal_force")->GetRange(range);
  EXPECT_DOUBLE_EQ(range[0], 3.0);
  // the line goes from the centre of `first` along the branch vector
  double a[3], b[3];
  strong->GetPoint(0, a);
  strong->GetPoint(1, b);
  EXPECT_NEAR(b[2] - a[2], 0.00099, 1e-15);
  EXPECT_EQ(forceChainPolyData(s, 10.0)->GetNumberOfLines(), 0);
  // tube radius grows with the force
  auto radius = all->GetPointData()->GetArray("tube_radius");
  EXPECT_GT(radius->GetTuple1(0), radius->GetTuple1(2));
}

TEST(UiSnapshotToVtk, CellBoxIsTheParallelepipedOfH) {
  Mat3 H;
  H << 0.01, 0.002, 0, 0, 0.01, 0, 0, 0, 0.02;
  auto box = cellBoxPolyData(H);
  EXPECT_EQ(box->GetNumberOfPoints(), 8);
  EXPECT_EQ(box->GetNumberOfLines(), 12);
  double x[3];
  box->GetPoint(7, x);
  EXPECT_NEAR(x[0], 0.012, 1e-15);
  EXPECT_NEAR(x[2], 0.02, 1e-15);
}

TEST(UiSnapshotToVtk, RoseOfIsotropicNormalsIsRoundAndMatchesFabricMeasures) {
  const auto normals = randomNormals(20000, 3);
  const FabricMeasures f = fabricFromNormals(normals);
  double a2 = 0;
  for (RosePlane p : {RosePlane::XZ, RosePlane::YZ, RosePlane::XY}) {
    const RoseHistogram h = roseHistogram(normals, {}, p, 36);
    ASSERT_EQ(h.density.size(), 36u);
    double mean = 0;
    for (double d : h.density) mean += d;
    EXPECT_NEAR(mean / 36.0, 1.0, 1e-12);  // normalised: isotropic = 1
    for (double d : h.density) EXPECT_NEAR(d, 1.0, 0.15);
    EXPECT_LT(h.anisotropy, 0.05);
    if (p != RosePlane::XY) a2 += 0.5 * h.anisotropy;
    auto poly = rosePolyData(h);
    EXPECT_EQ(poly->GetNumberOfPolys(), 36);
  }
  EXPECT_NEAR(a2, f.anisotropy2D, 1e-9);  // the same definition as measurements.hpp
}

TEST(UiSnapshotToVtk, RoseOfVerticalFabricPointsUp) {
  const auto normals = randomNormals(20000, 5, 2.0);  // more normals near the vertical
  const RoseHistogram h = roseHistogram(normals, {}, RosePlane::XZ, 36);
  EXPECT_GT(h.anisotropy, 0.3);
  EXPECT_NEAR(std::abs(h.direction), kPi / 2, 0.05);  // major direction along z
  EXPECT_GT(h.density[9], h.density[0]);             // bin at 90 deg vs 0 deg
  // force weighting changes the picture: weight horizontal normals heavily
  std::vector<double> w;
  for (const auto& n : normals) w.push_back(std::abs(n.z()) < 0.3 ? 100.0 : 1.0);
  const RoseHistogram hw = roseHistogram(normals, w, RosePlane::XZ, 36);
  EXPECT_NEAR(std::abs(hw.direction), 0.0, 0.1);
  auto guides = roseGuidesPolyData(h);
  EXPECT_EQ(guides->GetNumberOfLines(), 3);  // circle + two principal directions
}

TEST(UiSnapshotToVtk, SphericalRoseIsotropicIsAUnitSphere) {
  const auto normals = randomNormals(20000, 11);
  SphericalRose r = sphericalRose(normals, {}, 12, 20.0);
  ASSERT_GT(r.surface->GetNumberOfPoints(), 100);
  EXPECT_GT(r.minDensity, 0.8);
  EXPECT_LT(r.maxDensity, 1.2);
  EXPECT_EQ(r.axes->GetNumberOfLines(), 3);
  const auto vertical = randomNormals(20000, 13, 2.0);
  SphericalRose v = sphericalRose(vertical, {}, 12, 20.0);
  EXPECT_GT(v.maxDensity, 1.5);
}

TEST(UiDecimate, KeepsAtMostMaxPointsAndTheExtremes) {
  std::vector<PlotPoint> in;
  for (int i = 0; i < 100000; ++i) in.push_back({static_cast<double>(i), std::sin(i * 0.01)});
  in[54321].y = 7.0;   // a spike must survive
  in[12345].y = -5.0;
  const auto out = minMaxDecimate(in, 2000);
  EXPECT_LE(out.size(), 2000u);
  EXPECT_GT(out.size(), 1000u);
  double lo = 0, hi = 0;
  for (const auto& p : out) lo = std::min(lo, p.y), hi = std::max(hi, p.y);
  EXPECT_EQ(hi, 7.0);
  EXPECT_EQ(lo, -5.0);
  for (std::size_t i = 1; i < out.size(); ++i) EXPECT_LT(out[i - 1].x, out[i].x);  // order kept
  EXPECT_EQ(out.back().x, in.back().x);
  const std::vector<PlotPoint> small(10);
  EXPECT_EQ(minMaxDecimate(small, 2000).size(), 10u);
}
