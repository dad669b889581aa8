/*
 * Offscreen charts for reports: a plain-value description of an x–y chart (lines or markers, optional log
 * axes) rendered with Qt Charts into a PNG, without a window and without VTK (library fl_charts).
 * Long series are decimated before drawing (per bucket of consecutive points the first point and the
 * extremes in x and in y are kept, in order), so a 100-cycle tau–gamma loop keeps its tips and renders
 * fast. Non-finite points, and non-positive ones on a log axis, are skipped. Axis ranges cover all
 * series with a small margin. The PNG is written atomically (temporary file + rename): a reader sees the
 * old image or the new one, never half of one.
 * Threading: Qt widgets rule, i.e. call from the thread that owns the QApplication.
 */
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace fl::charts {

struct Series {
  std::string name;          // legend entry ("" = not in the legend)
  std::vector<double> x, y;  // same length; extra values of the longer one are ignored
  bool markers = false;      // line unless markers
};

struct Chart {
  std::string title, xLabel, yLabel;
  bool logX = false, logY = false;
  std::vector<Series> series;
  int width = 900, height = 600;  // [px]
};

// Most points drawn per series after decimation.
constexpr std::size_t kMaxPointsPerSeries = 2500;

// Renders offscreen to PNG (needs a QApplication; call ensureApplication() first when none exists).
// Throws fl::IoError naming the path on failure (fl::Error naming it when there is no QApplication).
void renderPng(const Chart& chart, const std::string& path);

// Creates a QApplication with the "offscreen" platform if none exists (it lives until the program ends).
void ensureApplication();

// The decimation used by renderPng (exposed for tests): indices of the kept points, increasing, always
// including the first and last; all indices when n <= maxPoints.
std::vector<std::size_t> decimateCurve(const std::vector<double>& x, const std::vector<double>& y,
                                       std::size_t maxPoints);

}  // namespace fl::charts
