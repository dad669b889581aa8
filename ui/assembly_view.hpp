/*
 * AssemblyView: the 3D view of the periodic assembly. Spheres are sphere impostors (vtkPointGaussianMapper
 * splats with a sphere shader, sized by "radius", coloured by the chosen field) so 4000 spheres stay fast
 * even with a software rasteriser;
 * force chains are drawn along branch vectors, coloured by the normal force and wider when stronger, shown
 * above a threshold (default: the mean normal force), as lines in three force bands (width 2, 4, 6 px);
 * the cell box is the parallelepiped of H; periodic
 * images are optional. VTK objects are built here, on the GUI thread, from the newest snapshot only.
 * Mouse rotate/zoom/pan come from VtkRenderWidget.
 */
#pragma once

#include <QWidget>

#include <array>
#include <memory>

#include <vtkSmartPointer.h>

#include "ui/snapshot.hpp"
#include "ui/snapshot_to_vtk.hpp"

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class vtkActor;
class vtkPointGaussianMapper;
class vtkLookupTable;
class vtkPolyDataMapper;
class vtkScalarBarActor;

namespace fl::ui {

class VtkRenderWidget;

// Render-time statistics of a view (from VtkRenderWidget::frameRendered).
struct FrameStats {
  long frames = 0;
  double totalMs = 0, maxMs = 0;
  double meanMs() const { return frames ? totalMs / static_cast<double>(frames) : 0.0; }
};

class AssemblyView : public QWidget {
  Q_OBJECT

 public:
  explicit AssemblyView(QWidget* parent = nullptr);
  ~AssemblyView() override;

  void setSnapshot(std::shared_ptr<const Snapshot> s);
  VtkRenderWidget* renderWidget() const { return m_view; }
  void setColorField(ColorField f);
  // Threshold as a multiple of the mean normal force (1 = the default, "above the mean").
  void setForceThresholdFactor(double f);
  void setShowForceChains(bool on);
  void setShowPeriodicImages(bool on);
  void setTranslucentSpheres(bool on);
  void resetCameraOnNextSnapshot() { m_cameraSet = false; }
  double currentForceThreshold() const { return m_threshold; }  // [N], of the last snapshot
  long shownForceChains() const { return m_shownChains; }
  long shownParticles() const { return m_shownParticles; }
  const FrameStats& frameStats() const { return m_frames; }
  void resetFrameStats() { m_frames = {}; }
  double lastBuildMs() const { return m_lastBuildMs; }  // time to build the VTK data of one snapshot

 private:
  void rebuild();

  VtkRenderWidget* m_view = nullptr;
  QComboBox* m_field = nullptr;
  QCheckBox* m_chains = nullptr;
  QCheckBox* m_images = nullptr;
  QCheckBox* m_translucent = nullptr;
  QDoubleSpinBox* m_thresholdFactor = nullptr;

  vtkSmartPointer<vtkPointGaussianMapper> m_particleMapper;
  vtkSmartPointer<vtkActor> m_particleActor;
  // force chains in three bands of normal force, drawn as lines of growing width (tubes from
  // vtkTubeFilter cost ~25 us each per frame with a software rasteriser: 150 ms for 6000 chains)
  static constexpr int kBands = 3;
  std::array<vtkSmartPointer<vtkPolyDataMapper>, kBands> m_chainMappers;
  std::array<vtkSmartPointer<vtkActor>, kBands> m_chainActors;
  vtkSmartPointer<vtkPolyDataMapper> m_boxMapper;
  vtkSmartPointer<vtkActor> m_boxActor;
  vtkSmartPointer<vtkLookupTable> m_particleLut, m_forceLut;
  vtkSmartPointer<vtkScalarBarActor> m_particleBar;

  std::shared_ptr<const Snapshot> m_snapshot;
  bool m_cameraSet = false;
  double m_threshold = 0;
  long m_shownChains = 0, m_shownParticles = 0;
  double m_lastBuildMs = 0;
  FrameStats m_frames;
};

}  // namespace fl::ui
