/*
 * PlotsView: the live plots (Qt Charts) of a run: the q–p' stress path, tau–gamma loops, Delta u
 * (undrained) or eps_v (drained) against cycles, and G_sec and Z per cycle (from Runner::cycles()).
 * Every series is min–max decimated to at most kMaxPointsPerSeries points (decimate.hpp) and the plots are
 * redrawn only when the time series grew, at most ~5 times a second, so 100 cycles of data stay
 * responsive; lastUpdateMs() reports the cost of one redraw.
 */
#pragma once

#include <QWidget>

#include <memory>

#include "ui/snapshot.hpp"

class QChart;
class QChartView;
class QLineSeries;
class QScatterSeries;
class QValueAxis;

namespace fl::ui {

class PlotsView : public QWidget {
  Q_OBJECT

 public:
  static constexpr std::size_t kMaxPointsPerSeries = 2000;

  explicit PlotsView(QWidget* parent = nullptr);
  ~PlotsView() override;

  void setSnapshot(std::shared_ptr<const Snapshot> s);
  // Redraws now from the given data regardless of the rate limit (tests, screenshots).
  void redraw(const Snapshot& s);

  // Points currently in each series (after decimation).
  int stressPathPoints() const;
  int loopPoints() const;
  int cyclePoints() const;   // du or eps_v series
  int stiffnessPoints() const;
  double lastUpdateMs() const { return m_lastUpdateMs; }
  double maxUpdateMs() const { return m_maxUpdateMs; }
  QChartView* stressPathView() const { return m_pathView; }
  QChartView* loopView() const { return m_loopView; }
  QChartView* cycleView() const { return m_cycleView; }
  QChartView* stiffnessView() const { return m_stiffView; }

 private:
  QChartView* m_pathView = nullptr;
  QChartView* m_loopView = nullptr;
  QChartView* m_cycleView = nullptr;
  QChartView* m_stiffView = nullptr;
  QLineSeries* m_path = nullptr;
  QLineSeries* m_loop = nullptr;
  QLineSeries* m_cycle = nullptr;
  QLineSeries* m_gsec = nullptr;
  QLineSeries* m_z = nullptr;
  QValueAxis* m_cycleY = nullptr;
  QValueAxis* m_zAxis = nullptr;

  std::shared_ptr<const Snapshot> m_pending;
  const void* m_shownSamples = nullptr;
  const void* m_shownCycles = nullptr;
  qint64 m_lastRedraw = -1000000;
  bool m_timerArmed = false;
  double m_lastUpdateMs = 0, m_maxUpdateMs = 0;
};

}  // namespace fl::ui
