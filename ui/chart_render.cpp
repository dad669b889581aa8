#include "ui/chart_render.hpp"

#include <QApplication>
#include <QBuffer>
#include <QChart>
#include <QGraphicsScene>
#include <QImage>
#include <QLegend>
#include <QLegendMarker>
#include <QLineSeries>
#include <QLogValueAxis>
#include <QPainter>
#include <QScatterSeries>
#include <QValueAxis>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "core/atomic_file.hpp"
#include "core/errors.hpp"

namespace fl::charts {

namespace {

// Distinct colours that survive greyscale printing reasonably (Okabe–Ito palette, then a few more).
const QColor kPalette[] = {QColor(0, 114, 178),  QColor(213, 94, 0),  QColor(0, 158, 115), QColor(204, 121, 167),
                           QColor(86, 180, 233), QColor(230, 159, 0), QColor(0, 0, 0),     QColor(120, 120, 120),
                           QColor(150, 40, 40),  QColor(40, 40, 150)};

struct Range {
  double lo = std::numeric_limits<double>::infinity(), hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool empty() const { return !(lo <= hi); }
};

bool usable(double v, bool log) { return std::isfinite(v) && (!log || v > 0); }

// A "nice" tick step (1, 2, 2.5 or 5 x 10^k) near `raw`.
double niceStep(double raw) {
  const double e = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / e;
  return (f <= 1.0 ? 1.0 : f <= 2.0 ? 2.0 : f <= 2.5 ? 2.5 : f <= 5.0 ? 5.0 : 10.0) * e;
}

// Linear axis: the data plus a 3 % margin (not crossing zero when the data does not), ticks at whole
// multiples of a nice step (about 6 intervals). A flat range is widened so the axis still has a span.
void setLinearRange(QValueAxis* axis, Range r) {
  if (r.empty()) r = {0.0, 1.0};
  double span = r.hi - r.lo;
  if (!(span > 0)) {
    span = std::max(std::abs(r.lo) * 0.1, 1e-12);
    r = {r.lo - 0.5 * span, r.hi + 0.5 * span};
  }
  double lo = r.lo - 0.03 * span, hi = r.hi + 0.03 * span;
  if (r.lo >= 0 && lo < 0) lo = 0;
  if (r.hi <= 0 && hi > 0) hi = 0;
  axis->setRange(lo, hi);
  axis->setTickType(QValueAxis::TicksDynamic);
  axis->setTickAnchor(0.0);
  axis->setTickInterval(niceStep((hi - lo) / 6.0));
  axis->setLabelFormat("%.4g");
}

void setLogRange(QLogValueAxis* axis, Range r) {
  if (r.empty()) r = {1.0, 10.0};
  double lo = std::pow(10.0, std::floor(std::log10(r.lo))), hi = std::pow(10.0, std::ceil(std::log10(r.hi)));
  if (!(hi > lo)) hi = lo * 10.0;
  axis->setBase(10.0);
  axis->setRange(lo * 0.9999, hi * 1.0001);  // just outside the decades, so both end labels are drawn
  axis->setLabelFormat("%g");
  axis->setMinorTickCount(8);
}

}  // namespace

std::vector<std::size_t> decimateCurve(const std::vector<double>& x, const std::vector<double>& y,
                                       std::size_t maxPoints) {
  const std::size_t n = std::min(x.size(), y.size());
  std::vector<std::size_t> out;
  maxPoints = std::max<std::size_t>(maxPoints, 6);
  if (n <= maxPoints) {
    out.resize(n);
    for (std::size_t i = 0; i < n; ++i) out[i] = i;
    return out;
  }
  // Up to 5 points per bucket (first, min/max x, min/max y), plus the last point of the series. Keeping the
  // x extremes matters for loops (tau–gamma): the strain reversals are their tips.
  const std::size_t buckets = (maxPoints - 1) / 5;
  out.reserve(maxPoints);
  for (std::size_t b = 0; b < buckets; ++b) {
    const std::size_t lo = b * n / buckets, hi = (b + 1) * n / buckets;
    if (lo >= hi) continue;
    std::size_t idx[5] = {lo, lo, lo, lo, lo};
    for (std::size_t i = lo + 1; i < hi; ++i) {
      // NaN compares false: a NaN never becomes an extreme, it is skipped at drawing time anyway
      if (x[i] < x[idx[1]]) idx[1] = i;
      if (x[i] > x[idx[2]]) idx[2] = i;
      if (y[i] < y[idx[3]]) idx[3] = i;
      if (y[i] > y[idx[4]]) idx[4] = i;
    }
    std::sort(idx, idx + 5);
    for (int k = 0; k < 5; ++k)
      if (k == 0 || idx[k] != idx[k - 1]) out.push_back(idx[k]);
  }
  if (out.empty() || out.back() != n - 1) out.push_back(n - 1);
  return out;
}

void ensureApplication() {
  if (QCoreApplication::instance()) return;
  // QApplication keeps references to argc/argv: they must outlive it.
  static int argc = 3;
  static char arg0[] = "fabriclab-charts", arg1[] = "-platform", arg2[] = "offscreen";
  static char* argv[] = {arg0, arg1, arg2, nullptr};
  static std::unique_ptr<QApplication> app = std::make_unique<QApplication>(argc, argv);
}

void renderPng(const Chart& spec, const std::string& path) {
  if (!qobject_cast<QApplication*>(QCoreApplication::instance()))
    throw Error(path + ": cannot render the chart: no QApplication (call fl::charts::ensureApplication() first)");
  if (spec.width < 16 || spec.height < 16 || spec.width > 20000 || spec.height > 20000)
    throw IoError(path + ": chart size " + std::to_string(spec.width) + " x " + std::to_string(spec.height) +
                  " px is outside 16..20000");

  // The scene owns the chart and, through it, the series and axes.
  QGraphicsScene scene;
  auto* chart = new QChart;
  scene.addItem(chart);
  chart->setTitle(QString::fromStdString(spec.title));
  QFont titleFont = chart->titleFont();
  titleFont.setPointSizeF(titleFont.pointSizeF() * 1.15);
  titleFont.setBold(true);
  chart->setTitleFont(titleFont);
  chart->setBackgroundRoundness(0);
  chart->setMargins(QMargins(6, 6, 12, 6));

  QAbstractAxis* xAxis = nullptr;
  QAbstractAxis* yAxis = nullptr;
  if (spec.logX) xAxis = new QLogValueAxis;
  else xAxis = new QValueAxis;
  if (spec.logY) yAxis = new QLogValueAxis;
  else yAxis = new QValueAxis;
  xAxis->setTitleText(QString::fromStdString(spec.xLabel));
  yAxis->setTitleText(QString::fromStdString(spec.yLabel));
  chart->addAxis(xAxis, Qt::AlignBottom);
  chart->addAxis(yAxis, Qt::AlignLeft);

  Range xr, yr;
  bool anyNamed = false;
  int colour = 0;
  for (const Series& s : spec.series) {
    const std::vector<std::size_t> keep = decimateCurve(s.x, s.y, kMaxPointsPerSeries);
    QList<QPointF> pts;
    pts.reserve(static_cast<qsizetype>(keep.size()));
    for (std::size_t i : keep) {
      const double xv = s.x[i], yv = s.y[i];
      if (!usable(xv, spec.logX) || !usable(yv, spec.logY)) continue;
      pts.append(QPointF(xv, yv));
      xr.add(xv);
      yr.add(yv);
    }
    const QColor c = kPalette[colour++ % (sizeof kPalette / sizeof kPalette[0])];
    QXYSeries* series = nullptr;
    if (s.markers) {
      auto* sc = new QScatterSeries;
      sc->setMarkerSize(7.0);
      sc->setColor(c);
      sc->setBorderColor(c.darker(130));
      series = sc;
    } else {
      auto* ln = new QLineSeries;
      QPen pen(c);
      pen.setWidthF(1.6);
      ln->setPen(pen);
      series = ln;
    }
    series->setName(QString::fromStdString(s.name));
    series->replace(pts);
    chart->addSeries(series);
    series->attachAxis(xAxis);
    series->attachAxis(yAxis);
    if (s.name.empty()) {
      for (QLegendMarker* m : chart->legend()->markers(series)) m->setVisible(false);
    } else {
      anyNamed = true;
    }
  }
  if (spec.logX) setLogRange(static_cast<QLogValueAxis*>(xAxis), xr);
  else setLinearRange(static_cast<QValueAxis*>(xAxis), xr);
  if (spec.logY) setLogRange(static_cast<QLogValueAxis*>(yAxis), yr);
  else setLinearRange(static_cast<QValueAxis*>(yAxis), yr);
  chart->legend()->setVisible(anyNamed);
  chart->legend()->setAlignment(Qt::AlignBottom);

  const QRectF rect(0, 0, spec.width, spec.height);
  chart->setGeometry(rect);
  scene.setSceneRect(rect);
  // Qt Charts lays out on posted events (layout requests, domain updates): deliver them before painting.
  QCoreApplication::sendPostedEvents();
  QCoreApplication::processEvents();

  QImage image(spec.width, spec.height, QImage::Format_ARGB32_Premultiplied);
  image.fill(Qt::white);
  {
    QPainter painter(&image);
    painter.setRenderHint(QPainter::Antialiasing, true);
    painter.setRenderHint(QPainter::TextAntialiasing, true);
    scene.render(&painter, rect, rect);
  }
  QByteArray bytes;
  QBuffer buffer(&bytes);
  buffer.open(QIODevice::WriteOnly);
  if (!image.save(&buffer, "PNG")) throw IoError(path + ": PNG encoding failed");
  buffer.close();
  writeFileAtomically(path, std::string(bytes.constData(), static_cast<std::size_t>(bytes.size())));
}

}  // namespace fl::charts
