/*
 * TeachingPanel: the "what you are seeing" dock. Short rich-text explanations of the quantities on screen
 * (p', q, tau–gamma, Z, Zm, a, K0, OCR, drained vs undrained, force chains, rose diagrams), written for a
 * student meeting DEM soil mechanics for the first time. Static text: nothing here depends on the run.
 */
#pragma once

#include <QTextBrowser>

namespace fl::ui {

class TeachingPanel : public QTextBrowser {
  Q_OBJECT

 public:
  explicit TeachingPanel(QWidget* parent = nullptr);
  static QString html();
};

}  // namespace fl::ui
