#include "ui/decimate.hpp"

#include <algorithm>

namespace fl::ui {

std::vector<PlotPoint> minMaxDecimate(const std::vector<PlotPoint>& in, std::size_t maxPoints) {
  maxPoints = std::max<std::size_t>(maxPoints, 4);
  if (in.size() <= maxPoints) return in;
  // Up to 3 points per bucket (first, min, max) plus the last point of the series.
  const std::size_t buckets = (maxPoints - 1) / 3;
  std::vector<PlotPoint> out;
  out.reserve(maxPoints);
  const std::size_t n = in.size();
  std::size_t lastIndex = n;  // index of the last point written
  for (std::size_t b = 0; b < buckets; ++b) {
    const std::size_t lo = b * n / buckets, hi = (b + 1) * n / buckets;
    if (lo >= hi) continue;
    std::size_t iMin = lo, iMax = lo;
    for (std::size_t i = lo + 1; i < hi; ++i) {
      if (in[i].y < in[iMin].y) iMin = i;
      if (in[i].y > in[iMax].y) iMax = i;
    }
    std::size_t idx[3] = {lo, iMin, iMax};
    std::sort(idx, idx + 3);
    for (int k = 0; k < 3; ++k)
      if (k == 0 || idx[k] != idx[k - 1]) {
        out.push_back(in[idx[k]]);
        lastIndex = idx[k];
      }
  }
  if (lastIndex != n - 1) out.push_back(in.back());
  return out;
}

}  // namespace fl::ui
