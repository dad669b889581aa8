/*
 * RoseView: rose diagrams of the contact normals, drawn with VTK in one render window split into four
 * viewports: polar histograms in the vertical planes x–z and y–z and the horizontal plane x–y (wedges,
 * isotropic reference circle, principal directions of the 2D fabric), and a 3D spherical histogram with
 * the principal directions of the fabric tensor. Optionally weighted by the normal force. Labels give both
 * anisotropy definitions, named: a_2D (Rothenburg–Bathurst, per plane and averaged over the vertical
 * planes as in measurements.hpp) and a_3D. Rebuilt from the newest snapshot at most ~5 times a second
 * (the spherical histogram is O(vertices x contacts)).
 */
#pragma once

#include <QWidget>

#include <array>
#include <memory>

#include <vtkSmartPointer.h>

#include "ui/snapshot.hpp"
#include "ui/snapshot_to_vtk.hpp"

class QCheckBox;
class vtkActor;
class vtkPolyDataMapper;
class vtkRenderer;
class vtkTextActor;
class vtkLookupTable;

namespace fl::ui {

class VtkRenderWidget;

class RoseView : public QWidget {
  Q_OBJECT

 public:
  explicit RoseView(QWidget* parent = nullptr);
  ~RoseView() override;

  void setSnapshot(std::shared_ptr<const Snapshot> s);
  void setWeighted(bool on);
  VtkRenderWidget* renderWidget() const { return m_view; }
  // Last computed values (for tests and labels).
  const RoseHistogram& histogram(RosePlane p) const { return m_hist[static_cast<int>(p)]; }
  double anisotropy2D() const { return m_a2D; }
  double anisotropy3D() const { return m_a3D; }
  long rebuilds() const { return m_rebuilds; }

 private:
  void rebuild();

  struct Panel {
    vtkSmartPointer<vtkRenderer> renderer;
    vtkSmartPointer<vtkPolyDataMapper> mapper, guideMapper;
    vtkSmartPointer<vtkActor> actor, guides;
    vtkSmartPointer<vtkTextActor> label;
  };
  VtkRenderWidget* m_view = nullptr;
  QCheckBox* m_weighted = nullptr;
  std::array<Panel, 4> m_panels;  // XZ, YZ, XY, 3D
  vtkSmartPointer<vtkLookupTable> m_lut;
  std::array<RoseHistogram, 3> m_hist;
  double m_a2D = 0, m_a3D = 0;
  long m_rebuilds = 0;
  std::shared_ptr<const Snapshot> m_snapshot;
  long m_shownSerial = -1;
  qint64 m_lastBuild = -1000000;
  bool m_pending = false;
};

}  // namespace fl::ui
