#include "ui/rose_view.hpp"

#include <QCheckBox>
#include <QDateTime>
#include <QTimer>
#include <QVBoxLayout>

#include <cmath>
#include <cstdio>

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkLookupTable.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

#include "core/measurements.hpp"
#include "ui/vtk_render_widget.hpp"

namespace fl::ui {

namespace {
constexpr double kViewports[4][4] = {{0.0, 0.5, 0.5, 1.0}, {0.5, 0.5, 1.0, 1.0}, {0.0, 0.0, 0.5, 0.5}, {0.5, 0.0, 1.0, 0.5}};
constexpr int kMinIntervalMs = 200;
}  // namespace

RoseView::RoseView(QWidget* parent) : QWidget(parent) {
  m_view = new VtkRenderWidget(this);
  m_view->setMinimumSize(300, 300);
  m_view->setToolTip(tr("Rose diagrams: how many contact normals point in each direction (1 = isotropic, the "
                        "circle). Lines: principal directions of the fabric. Drag the 3D panel to rotate it."));
  m_weighted = new QCheckBox(tr("weight by normal force"), this);
  m_weighted->setToolTip(tr("Count each contact in proportion to its normal force: shows the directions that "
                            "carry the load rather than the directions of all contacts."));
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->addWidget(m_weighted);
  layout->addWidget(m_view, 1);

  m_lut = vtkSmartPointer<vtkLookupTable>::New();
  m_lut->SetHueRange(0.6, 0.0);
  m_lut->SetTableRange(0.5, 1.5);
  m_lut->Build();

  for (int k = 0; k < 4; ++k) {
    Panel& p = m_panels[static_cast<std::size_t>(k)];
    p.renderer = k == 0 ? vtkSmartPointer<vtkRenderer>(m_view->renderer()) : vtkSmartPointer<vtkRenderer>::New();
    p.renderer->SetViewport(kViewports[k][0], kViewports[k][1], kViewports[k][2], kViewports[k][3]);
    p.renderer->SetBackground(0.1 + 0.02 * (k % 2), 0.11, 0.14);
    p.renderer->SetBackgroundAlpha(1.0);
    if (k > 0) m_view->renderWindow()->AddRenderer(p.renderer);
    p.mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
    p.mapper->SetLookupTable(m_lut);
    p.mapper->SetInputData(vtkSmartPointer<vtkPolyData>::New());
    p.actor = vtkSmartPointer<vtkActor>::New();
    p.actor->SetMapper(p.mapper);
    p.guideMapper = vtkSmartPointer<vtkPolyDataMapper>::New();
    p.guideMapper->SetInputData(vtkSmartPointer<vtkPolyData>::New());
    p.guideMapper->ScalarVisibilityOff();
    p.guides = vtkSmartPointer<vtkActor>::New();
    p.guides->SetMapper(p.guideMapper);
    p.guides->GetProperty()->SetColor(1.0, 1.0, 1.0);
    p.guides->GetProperty()->SetLineWidth(2.0);
    p.label = vtkSmartPointer<vtkTextActor>::New();
    p.label->GetTextProperty()->SetFontSize(13);
    p.label->GetTextProperty()->SetColor(0.95, 0.95, 0.95);
    p.label->SetPosition(6, 6);
    p.renderer->AddActor(p.actor);
    p.renderer->AddActor(p.guides);
    p.renderer->AddViewProp(p.label);
    vtkCamera* cam = p.renderer->GetActiveCamera();
    if (k < 3) {
      // 2D panels: look straight at the plane; not interactive, so the mouse only turns the 3D panel
      cam->ParallelProjectionOn();
      cam->SetPosition(0, 0, 10);
      cam->SetFocalPoint(0, 0, 0);
      cam->SetViewUp(0, 1, 0);
      cam->SetParallelScale(1.9);
      p.renderer->InteractiveOff();
    } else {
      cam->SetPosition(4.5, -6.0, 3.5);
      cam->SetFocalPoint(0, 0, 0);
      cam->SetViewUp(0, 0, 1);
    }
  }
  connect(m_weighted, &QCheckBox::toggled, this, [this] {
    m_shownSerial = -1;
    rebuild();
  });
}

RoseView::~RoseView() = default;

void RoseView::setWeighted(bool on) { m_weighted->setChecked(on); }

void RoseView::setSnapshot(std::shared_ptr<const Snapshot> s) {
  m_snapshot = std::move(s);
  const qint64 now = QDateTime::currentMSecsSinceEpoch();
  if (now - m_lastBuild >= kMinIntervalMs) {
    rebuild();
  } else if (!m_pending) {
    m_pending = true;
    QTimer::singleShot(static_cast<int>(kMinIntervalMs - (now - m_lastBuild)), this, [this] {
      m_pending = false;
      rebuild();
    });
  }
}

void RoseView::rebuild() {
  if (!m_snapshot || m_snapshot->serial == m_shownSerial) return;
  m_shownSerial = m_snapshot->serial;
  m_lastBuild = QDateTime::currentMSecsSinceEpoch();
  ++m_rebuilds;
  const std::vector<Vec3> normals = m_snapshot->contactNormals();
  std::vector<double> weights;
  if (m_weighted->isChecked()) {
    weights = m_snapshot->contactForces();
    double mean = 0;
    for (double w : weights) mean += w;
    mean = weights.empty() ? 1.0 : mean / static_cast<double>(weights.size());
    for (double& w : weights) w = mean > 0 ? w / mean : 1.0;
  }
  const FabricMeasures fabric = fabricFromNormals(normals);
  m_a2D = fabric.anisotropy2D;
  m_a3D = fabric.anisotropy3D;
  const char* weightNote = weights.empty() ? "" : " (force-weighted)";
  char text[256];
  for (int k = 0; k < 3; ++k) {
    const auto plane = static_cast<RosePlane>(k);
    m_hist[static_cast<std::size_t>(k)] = roseHistogram(normals, weights, plane, 36);
    const RoseHistogram& h = m_hist[static_cast<std::size_t>(k)];
    Panel& p = m_panels[static_cast<std::size_t>(k)];
    p.mapper->SetInputData(rosePolyData(h));
    p.mapper->SetScalarRange(0.5, 1.5);
    p.guideMapper->SetInputData(roseGuidesPolyData(h));
    std::snprintf(text, sizeof text, "%s%s\na_2D (Rothenburg-Bathurst) = %.3f\nmajor axis at %.0f deg from %s",
                  rosePlaneName(plane), weightNote, h.anisotropy, h.direction * 180.0 / kPi, k == 1 ? "y" : "x");
    p.label->SetInput(text);
  }
  SphericalRose sphere = sphericalRose(normals, weights, 16, 15.0);
  Panel& p = m_panels[3];
  p.mapper->SetInputData(sphere.surface);
  p.mapper->SetScalarRange(0.5, 1.5);
  p.guideMapper->SetInputData(sphere.axes);
  std::snprintf(text, sizeof text,
                "3D spherical histogram%s\na_3D = %.3f   a_2D (R-B, vertical planes) = %.3f\ncontacts: %zu",
                weightNote, m_a3D, m_a2D, normals.size());
  p.label->SetInput(text);
  m_view->update();
}

}  // namespace fl::ui
