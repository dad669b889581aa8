/*
 * Snapshot -> VTK conversions (house-style §15): pure functions from plain snapshot data to vtkPolyData,
 * with no window, renderer or Qt involved, so they are unit-tested on their own. The views only wire the
 * results into mappers. Array names used by the views:
 *   particles:    points = centres, point data "radius" [m] and "field" (the chosen colour field);
 *   force chains: one line per contact from the centre of `first` along the branch vector, point and cell
 *                 data "normal_force" [N] and point data "tube_radius" [m] (width grows with the force);
 *   cell box:     8 corners of the parallelepiped spanned by the columns of H, 12 lines;
 *   roses:        a polar histogram (wedges, cell data "density", 1 = isotropic) in the plane's own 2D
 *                 coordinates, a spherical histogram (a sphere whose radius is the directional density).
 * Contact normals are directionless, so every normal counts as both n and -n in the histograms.
 */
#pragma once

#include <array>
#include <limits>
#include <vector>

#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include "ui/snapshot.hpp"

namespace fl::ui {

enum class ColorField { Size, Speed, ContactCount, MeanStress };
const char* colorFieldName(ColorField f);  // with unit, for legends
constexpr std::array<ColorField, 4> kColorFields = {ColorField::Size, ColorField::Speed, ColorField::ContactCount,
                                                    ColorField::MeanStress};

// Per-particle values of a colour field (radius [m], |v'| [m/s], contacts, p_p [Pa]).
std::vector<double> particleField(const Snapshot& s, ColorField f);

// Particles as points with "radius" and "field"; with periodicImages, particles cut by a cell face are
// repeated at their images across that face (so the box looks filled like the periodic medium).
vtkSmartPointer<vtkPolyData> particlesPolyData(const Snapshot& s, ColorField f, bool periodicImages = false);

// Contacts whose normal force exceeds `threshold` [N] (default in the GUI: the mean normal force) and is at
// most `upper` [N] (the view draws force bands with growing line widths).
vtkSmartPointer<vtkPolyData> forceChainPolyData(const Snapshot& s, double threshold,
                                                double upper = std::numeric_limits<double>::infinity());

vtkSmartPointer<vtkPolyData> cellBoxPolyData(const Mat3& H);

// ---- rose diagrams ----
enum class RosePlane { XZ, YZ, XY };
const char* rosePlaneName(RosePlane p);

struct RoseHistogram {
  RosePlane plane = RosePlane::XZ;
  std::vector<double> density;  // per bin over [0, 2 pi), normalised so that isotropic = 1
  double anisotropy = 0;        // a = 2 (lambda1 - lambda2) of the 2D fabric (Rothenburg–Bathurst)
  double direction = 0;         // major principal direction, angle from the plane's first axis [rad]
  std::size_t contacts = 0;
};
// Normals projected on the plane (normalised again); weights empty = unweighted, else one per normal.
RoseHistogram roseHistogram(const std::vector<Vec3>& normals, const std::vector<double>& weights, RosePlane plane,
                            int bins = 36);
// Wedges in the plane's 2D coordinates (x = first axis, y = second, z = 0), cell data "density".
vtkSmartPointer<vtkPolyData> rosePolyData(const RoseHistogram& h);
// The isotropic reference circle (radius 1) and the two principal directions (major longer).
vtkSmartPointer<vtkPolyData> roseGuidesPolyData(const RoseHistogram& h);

struct SphericalRose {
  vtkSmartPointer<vtkPolyData> surface;  // radius = density in that direction, point data "density"
  vtkSmartPointer<vtkPolyData> axes;     // principal fabric directions, half-length 1.3 x 3 lambda_k (out of the surface)
  double minDensity = 0, maxDensity = 0;
};
// Density estimated by counting normals within a cone of half-angle `coneDegrees` about each vertex.
SphericalRose sphericalRose(const std::vector<Vec3>& normals, const std::vector<double>& weights,
                            int resolution = 24, double coneDegrees = 15.0);

// Weighted fabric tensor phi = sum w n n / sum w (trace 1); weights empty = unweighted.
Mat3 weightedFabric(const std::vector<Vec3>& normals, const std::vector<double>& weights);

}  // namespace fl::ui
