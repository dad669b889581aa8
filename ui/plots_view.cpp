#include "ui/plots_view.hpp"

#include <QChart>
#include <QChartView>
#include <QDateTime>
#include <QElapsedTimer>
#include <QGridLayout>
#include <QLineSeries>
#include <QPainter>
#include <QTimer>
#include <QValueAxis>

#include <algorithm>
#include <map>

#include "ui/decimate.hpp"

namespace fl::ui {

namespace {

constexpr int kMinIntervalMs = 200;

QChartView* makeChart(QWidget* parent, const QString& title, const QString& xTitle, const QString& yTitle,
                      const QString& tip, QLineSeries* series, QValueAxis** yAxisOut = nullptr) {
  auto* chart = new QChart;
  chart->setTitle(title);
  chart->legend()->hide();
  chart->addSeries(series);
  auto* x = new QValueAxis;
  x->setTitleText(xTitle);
  x->setLabelFormat("%.3g");
  auto* y = new QValueAxis;
  y->setTitleText(yTitle);
  y->setLabelFormat("%.3g");
  chart->addAxis(x, Qt::AlignBottom);
  chart->addAxis(y, Qt::AlignLeft);
  series->attachAxis(x);
  series->attachAxis(y);
  chart->setMargins(QMargins(2, 2, 2, 2));
  auto* view = new QChartView(chart, parent);
  view->setRenderHint(QPainter::Antialiasing, false);  // cheaper redraws with thousands of points
  view->setMinimumSize(240, 180);
  view->setToolTip(tip);
  if (yAxisOut) *yAxisOut = y;
  return view;
}

void fit(QLineSeries* series, const std::vector<PlotPoint>& pts) {
  const auto axes = series->attachedAxes();
  double x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  if (!pts.empty()) {
    x0 = x1 = pts[0].x;
    y0 = y1 = pts[0].y;
    for (const auto& p : pts) {
      x0 = std::min(x0, p.x);
      x1 = std::max(x1, p.x);
      y0 = std::min(y0, p.y);
      y1 = std::max(y1, p.y);
    }
  }
  const double mx = std::max((x1 - x0) * 0.05, 1e-12), my = std::max((y1 - y0) * 0.05, 1e-12);
  for (auto* axis : axes) {
    auto* v = qobject_cast<QValueAxis*>(axis);
    if (!v) continue;
    if (v->orientation() == Qt::Horizontal) v->setRange(x0 - mx, x1 + mx);
    else v->setRange(y0 - my, y1 + my);
  }
}

void setPoints(QLineSeries* series, const std::vector<PlotPoint>& raw) {
  const std::vector<PlotPoint> pts = minMaxDecimate(raw, PlotsView::kMaxPointsPerSeries);
  QList<QPointF> list;
  list.reserve(static_cast<qsizetype>(pts.size()));
  for (const auto& p : pts) list.append(QPointF(p.x, p.y));
  series->replace(list);
  fit(series, pts);
}

}  // namespace

PlotsView::PlotsView(QWidget* parent) : QWidget(parent) {
  m_path = new QLineSeries;
  m_loop = new QLineSeries;
  m_cycle = new QLineSeries;
  m_gsec = new QLineSeries;
  m_z = new QLineSeries;
  m_pathView = makeChart(this, tr("Stress path"), tr("p' [kPa]"), tr("q [kPa]"),
                         tr("Mean effective stress p' = (s1+s2+s3)/3 against deviator stress q = s_zz - (s_xx+s_yy)/2."),
                         m_path);
  m_loopView = makeChart(this, tr("Shear stress - shear strain"), tr("gamma [%]"), tr("tau [kPa]"),
                         tr("tau = q/2 against gamma = eps_a - eps_r: each closed loop is one cycle; its slope is "
                            "the secant stiffness G_sec and its area the energy dissipated."),
                         m_loop);
  m_cycleView = makeChart(this, tr("Pore pressure / volume change"), tr("cycles"), tr("Delta u [kPa]"),
                          tr("Undrained (constant volume): excess pore pressure Delta u = drop of the lateral "
                             "effective stress. Drained: volumetric strain eps_v."),
                          m_cycle, &m_cycleY);
  m_stiffView = makeChart(this, tr("Per cycle"), tr("cycle"), tr("G_sec [MPa]"),
                          tr("Secant shear stiffness G_sec = (tau_max - tau_min)/(gamma_max - gamma_min) of each "
                             "cycle, and the coordination number Z at its end (right axis)."),
                          m_gsec);
  // Z on a second axis of the per-cycle chart
  QChart* chart = m_stiffView->chart();
  chart->addSeries(m_z);
  m_zAxis = new QValueAxis;
  m_zAxis->setTitleText(tr("Z"));
  m_zAxis->setLabelFormat("%.3g");
  chart->addAxis(m_zAxis, Qt::AlignRight);
  m_z->attachAxis(chart->axes(Qt::Horizontal).first());
  m_z->attachAxis(m_zAxis);
  m_gsec->setName(tr("G_sec"));
  m_z->setName(tr("Z"));
  chart->legend()->show();
  for (auto* s : {m_gsec, m_z}) s->setPointsVisible(true);

  auto* grid = new QGridLayout(this);
  grid->setContentsMargins(0, 0, 0, 0);
  grid->addWidget(m_pathView, 0, 0);
  grid->addWidget(m_loopView, 0, 1);
  grid->addWidget(m_cycleView, 1, 0);
  grid->addWidget(m_stiffView, 1, 1);
}

PlotsView::~PlotsView() = default;

int PlotsView::stressPathPoints() const { return static_cast<int>(m_path->count()); }
int PlotsView::loopPoints() const { return static_cast<int>(m_loop->count()); }
int PlotsView::cyclePoints() const { return static_cast<int>(m_cycle->count()); }
int PlotsView::stiffnessPoints() const { return static_cast<int>(m_gsec->count()); }

void PlotsView::setSnapshot(std::shared_ptr<const Snapshot> s) {
  if (!s) return;
  // only the time series matter here: skip snapshots whose series did not grow
  if (s->samples.get() == m_shownSamples && s->cycles.get() == m_shownCycles) return;
  m_pending = std::move(s);
  const qint64 now = QDateTime::currentMSecsSinceEpoch();
  if (now - m_lastRedraw >= kMinIntervalMs) {
    redraw(*m_pending);
  } else if (!m_timerArmed) {
    m_timerArmed = true;
    QTimer::singleShot(static_cast<int>(kMinIntervalMs - (now - m_lastRedraw)), this, [this] {
      m_timerArmed = false;
      if (m_pending) redraw(*m_pending);
    });
  }
}

void PlotsView::redraw(const Snapshot& s) {
  QElapsedTimer timer;
  timer.start();
  m_lastRedraw = QDateTime::currentMSecsSinceEpoch();
  m_shownSamples = s.samples.get();
  m_shownCycles = s.cycles.get();
  static const std::vector<Sample> kNoSamples;
  static const std::vector<CycleRecord> kNoCycles;
  const auto& samples = s.samples ? *s.samples : kNoSamples;
  const auto& cycles = s.cycles ? *s.cycles : kNoCycles;

  std::vector<PlotPoint> path, loop, cyc, gsec, z;
  path.reserve(samples.size());
  bool anyCyclic = false;
  for (const auto& x : samples) {
    path.push_back({x.p / 1e3, x.q / 1e3});
    anyCyclic = anyCyclic || x.cycle > 0;
  }
  // tau–gamma: the cyclic stages if any, else everything (a monotonic test still has a tau–gamma curve)
  for (const auto& x : samples)
    if (!anyCyclic || x.cycle > 0) loop.push_back({x.gamma * 100.0, x.tau / 1e3});
  // Delta u or eps_v against the (fractional) cycle count: samples of a cycle spread evenly over it
  bool undrained = false;
  std::map<std::pair<int, int>, int> perCycle;  // (stage, cycle) -> samples
  for (const auto& x : samples)
    if (x.cycle > 0) {
      ++perCycle[{x.stage, x.cycle}];
      if (x.stage >= 0 && x.stage < static_cast<int>(s.stages.size()))
        undrained = undrained || s.stages[static_cast<std::size_t>(x.stage)].drainage == Drainage::Undrained;
    }
  std::map<std::pair<int, int>, int> seen;
  for (const auto& x : samples) {
    if (x.cycle <= 0) continue;
    const int i = seen[{x.stage, x.cycle}]++;
    const double pos = (x.cycle - 1) + static_cast<double>(i + 1) / perCycle[{x.stage, x.cycle}];
    cyc.push_back({pos, undrained ? x.du / 1e3 : x.epsV * 100.0});
  }
  m_cycleY->setTitleText(undrained ? tr("Delta u [kPa]") : tr("eps_v [%]"));
  m_cycleView->chart()->setTitle(undrained ? tr("Excess pore pressure (undrained)")
                                           : tr("Volumetric strain (drained)"));
  for (const auto& c : cycles) {
    gsec.push_back({static_cast<double>(c.cycle), c.Gsec / 1e6});
    z.push_back({static_cast<double>(c.cycle), c.end.Z});
  }
  setPoints(m_path, path);
  setPoints(m_loop, loop);
  setPoints(m_cycle, cyc);
  setPoints(m_gsec, gsec);
  {
    const std::vector<PlotPoint> pts = minMaxDecimate(z, kMaxPointsPerSeries);
    QList<QPointF> list;
    for (const auto& p : pts) list.append(QPointF(p.x, p.y));
    m_z->replace(list);
    double lo = 0, hi = 1;
    if (!pts.empty()) {
      lo = hi = pts[0].y;
      for (const auto& p : pts) lo = std::min(lo, p.y), hi = std::max(hi, p.y);
    }
    const double m = std::max((hi - lo) * 0.05, 1e-3);
    m_zAxis->setRange(lo - m, hi + m);
  }
  m_lastUpdateMs = static_cast<double>(timer.nsecsElapsed()) / 1e6;
  m_maxUpdateMs = std::max(m_maxUpdateMs, m_lastUpdateMs);
}

}  // namespace fl::ui
