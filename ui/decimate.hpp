/*
 * Min–max decimation of a plotted series: keeps the plots responsive however long a run gets (100
 * cycles x 40 samples and more). The series is cut into buckets of consecutive points; each bucket keeps
 * its first point and the points with the smallest and largest y, in their original order, so peaks of a
 * tau–gamma loop or a Delta-u spike are never dropped. Pure, no Qt.
 */
#pragma once

#include <cstddef>
#include <vector>

namespace fl::ui {

struct PlotPoint {
  double x = 0, y = 0;
};

// Returns at most maxPoints points (maxPoints >= 4); the input is returned unchanged when it fits.
std::vector<PlotPoint> minMaxDecimate(const std::vector<PlotPoint>& in, std::size_t maxPoints);

}  // namespace fl::ui
