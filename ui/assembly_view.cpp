#include "ui/assembly_view.hpp"

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QElapsedTimer>
#include <QHBoxLayout>
#include <QLabel>
#include <QVBoxLayout>

#include <algorithm>
#include <limits>

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkPointGaussianMapper.h>
#include <vtkLookupTable.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkSphereSource.h>
#include <vtkTextProperty.h>

#include "ui/vtk_render_widget.hpp"

namespace fl::ui {

AssemblyView::AssemblyView(QWidget* parent) : QWidget(parent) {
  m_view = new VtkRenderWidget(this);
  m_view->setMinimumSize(320, 240);
  m_view->setToolTip(tr("The periodic cell of spheres. Drag: rotate; right-drag or wheel: zoom; "
                        "middle-drag: pan."));
  connect(m_view, &VtkRenderWidget::frameRendered, this, [this](double ms) {
    ++m_frames.frames;
    m_frames.totalMs += ms;
    m_frames.maxMs = std::max(m_frames.maxMs, ms);
  });

  m_field = new QComboBox(this);
  for (ColorField f : kColorFields) m_field->addItem(colorFieldName(f), static_cast<int>(f));
  m_field->setToolTip(tr("Colour of the spheres. Particle mean stress p_p = (1/3V_p) sum F_n (r - delta/2): "
                         "the particle's own average stress, larger than p' by about 1/solid fraction."));
  m_chains = new QCheckBox(tr("force chains"), this);
  m_chains->setChecked(true);
  m_chains->setToolTip(tr("Contacts carrying more than the threshold, drawn from centre to centre; "
                          "thicker and redder = larger normal force."));
  m_thresholdFactor = new QDoubleSpinBox(this);
  m_thresholdFactor->setRange(0.0, 10.0);
  m_thresholdFactor->setSingleStep(0.1);
  m_thresholdFactor->setValue(1.0);
  m_thresholdFactor->setSuffix(tr(" x mean F_n"));
  m_thresholdFactor->setToolTip(tr("Show contacts whose normal force exceeds this multiple of the mean "
                                   "normal force (1 = above the mean, the usual definition of a strong chain)."));
  m_translucent = new QCheckBox(tr("translucent spheres"), this);
  m_translucent->setToolTip(tr("See the force chains through the particles."));
  m_images = new QCheckBox(tr("periodic images"), this);
  m_images->setToolTip(tr("Repeat particles cut by a cell face on the opposite side, as in the periodic medium."));

  auto* controls = new QHBoxLayout;
  controls->addWidget(new QLabel(tr("Colour:"), this));
  controls->addWidget(m_field);
  controls->addWidget(m_chains);
  controls->addWidget(m_thresholdFactor);
  controls->addWidget(m_translucent);
  controls->addWidget(m_images);
  controls->addStretch();
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->addLayout(controls);
  layout->addWidget(m_view, 1);

  // Spheres as impostors: one point per particle drawn as a camera-facing disc of the particle's radius,
  // shaded like a sphere in the fragment shader. Mesh glyphs (vtkGlyph3DMapper) cost ~0.3 s a frame for
  // 4000 spheres with Mesa's software rasteriser; impostors draw the same picture in a few ms.
  m_particleLut = vtkSmartPointer<vtkLookupTable>::New();
  m_particleLut->SetHueRange(0.667, 0.0);  // blue (low) to red (high)
  m_particleLut->Build();
  m_particleMapper = vtkSmartPointer<vtkPointGaussianMapper>::New();
  m_particleMapper->SetScaleArray("radius");
  m_particleMapper->SetScaleFactor(1.0);
  m_particleMapper->SetTriangleScale(1.0);  // the disc has radius 1 x scale: no larger triangles needed
  m_particleMapper->EmissiveOff();
  m_particleMapper->SetSplatShaderCode(
      "//VTK::Color::Impl\n"
      "float dist2 = dot(offsetVCVSOutput.xy, offsetVCVSOutput.xy);\n"
      "if (dist2 > 1.0) { discard; }\n"
      "float nz = sqrt(1.0 - dist2);\n"
      "ambientColor *= 0.35 + 0.65 * nz;\n"
      "diffuseColor *= 0.35 + 0.65 * nz;\n");
  m_particleMapper->SetScalarModeToUsePointFieldData();
  m_particleMapper->SelectColorArray("field");
  m_particleMapper->SetLookupTable(m_particleLut);
  m_particleMapper->SetInputData(vtkNew<vtkPolyData>().GetPointer());
  m_particleActor = vtkSmartPointer<vtkActor>::New();
  m_particleActor->SetMapper(m_particleMapper);

  m_forceLut = vtkSmartPointer<vtkLookupTable>::New();
  m_forceLut->SetHueRange(0.15, 0.0);  // yellow to red
  m_forceLut->SetSaturationRange(1.0, 1.0);
  m_forceLut->SetValueRange(0.9, 0.7);
  m_forceLut->Build();
  for (int k = 0; k < kBands; ++k) {
    auto& mapper = m_chainMappers[static_cast<std::size_t>(k)];
    auto& actor = m_chainActors[static_cast<std::size_t>(k)];
    mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
    mapper->SetInputData(vtkNew<vtkPolyData>().GetPointer());
    mapper->SetScalarModeToUseCellFieldData();
    mapper->SelectColorArray("normal_force");
    mapper->SetLookupTable(m_forceLut);
    mapper->ScalarVisibilityOn();
    actor = vtkSmartPointer<vtkActor>::New();
    actor->SetMapper(mapper);
    actor->GetProperty()->SetLineWidth(2.0f * static_cast<float>(k + 1));
    actor->GetProperty()->SetLighting(false);
  }

  m_boxMapper = vtkSmartPointer<vtkPolyDataMapper>::New();
  m_boxMapper->SetInputData(cellBoxPolyData(Mat3::Identity()));
  m_boxActor = vtkSmartPointer<vtkActor>::New();
  m_boxActor->SetMapper(m_boxMapper);
  m_boxActor->GetProperty()->SetColor(0.9, 0.9, 0.9);
  m_boxActor->GetProperty()->SetLineWidth(2.0);

  m_particleBar = vtkSmartPointer<vtkScalarBarActor>::New();
  m_particleBar->SetLookupTable(m_particleLut);
  m_particleBar->SetNumberOfLabels(4);
  m_particleBar->SetWidth(0.08);
  m_particleBar->SetHeight(0.5);
  m_particleBar->SetPosition(0.9, 0.1);
  m_particleBar->GetLabelTextProperty()->SetFontSize(10);
  m_particleBar->SetLabelFormat("%-#6.3g");

  vtkRenderer* r = m_view->renderer();
  r->SetBackground(0.12, 0.13, 0.16);
  r->AddActor(m_particleActor);
  for (auto& a : m_chainActors) r->AddActor(a);
  r->AddActor(m_boxActor);
  r->AddViewProp(m_particleBar);

  auto changed = [this] { rebuild(); };
  connect(m_field, qOverload<int>(&QComboBox::currentIndexChanged), this, changed);
  connect(m_chains, &QCheckBox::toggled, this, changed);
  connect(m_images, &QCheckBox::toggled, this, changed);
  connect(m_translucent, &QCheckBox::toggled, this, changed);
  connect(m_thresholdFactor, qOverload<double>(&QDoubleSpinBox::valueChanged), this, changed);
}

AssemblyView::~AssemblyView() = default;

void AssemblyView::setColorField(ColorField f) { m_field->setCurrentIndex(m_field->findData(static_cast<int>(f))); }
void AssemblyView::setForceThresholdFactor(double f) { m_thresholdFactor->setValue(f); }
void AssemblyView::setShowForceChains(bool on) { m_chains->setChecked(on); }
void AssemblyView::setShowPeriodicImages(bool on) { m_images->setChecked(on); }
void AssemblyView::setTranslucentSpheres(bool on) { m_translucent->setChecked(on); }

void AssemblyView::setSnapshot(std::shared_ptr<const Snapshot> s) {
  m_snapshot = std::move(s);
  rebuild();
}

void AssemblyView::rebuild() {
  if (!m_snapshot) return;
  QElapsedTimer timer;
  timer.start();
  const Snapshot& s = *m_snapshot;
  const auto field = static_cast<ColorField>(m_field->currentData().toInt());

  auto particles = particlesPolyData(s, field, m_images->isChecked());
  m_shownParticles = particles->GetNumberOfPoints();
  m_particleMapper->SetInputData(particles);
  double range[2] = {0.0, 1.0};
  if (m_shownParticles > 0) particles->GetPointData()->GetArray("field")->GetRange(range);
  if (range[1] <= range[0]) range[1] = range[0] + 1e-12;
  m_particleMapper->SetScalarRange(range);
  m_particleLut->SetTableRange(range);
  m_particleBar->SetTitle(colorFieldName(field));
  m_particleActor->GetProperty()->SetOpacity(m_translucent->isChecked() ? 0.25 : 1.0);

  m_threshold = m_thresholdFactor->value() * s.meanNormalForce();
  m_shownChains = 0;
  double maxForce = m_threshold;
  for (const auto& c : s.contacts) maxForce = std::max(maxForce, c.normalForce);
  for (int k = 0; k < kBands; ++k) {
    auto& actor = m_chainActors[static_cast<std::size_t>(k)];
    if (!m_chains->isChecked()) {
      actor->SetVisibility(false);
      continue;
    }
    // equal bands of force between the threshold and the strongest contact
    const double lo = k == 0 ? m_threshold : m_threshold + (maxForce - m_threshold) * k / kBands;
    const double hi = k == kBands - 1 ? std::numeric_limits<double>::infinity()
                                      : m_threshold + (maxForce - m_threshold) * (k + 1) / kBands;
    auto chains = forceChainPolyData(s, lo, hi);
    m_shownChains += chains->GetNumberOfLines();
    auto& mapper = m_chainMappers[static_cast<std::size_t>(k)];
    mapper->SetInputData(chains);
    mapper->SetScalarRange(m_threshold, std::max(maxForce, m_threshold * 1.0001 + 1e-30));
    actor->SetVisibility(chains->GetNumberOfLines() > 0);
  }
  m_boxMapper->SetInputData(cellBoxPolyData(s.cell));

  if (!m_cameraSet && m_shownParticles > 0) {
    // a three-quarter view from above, z (axial) up
    vtkCamera* cam = m_view->renderer()->GetActiveCamera();
    const Vec3 c = s.cell * Vec3(0.5, 0.5, 0.5);
    cam->SetFocalPoint(c.x(), c.y(), c.z());
    cam->SetPosition(c.x() + 2.2 * s.cell(0, 0), c.y() - 3.0 * s.cell(1, 1), c.z() + 1.6 * s.cell(2, 2));
    cam->SetViewUp(0, 0, 1);
    m_view->renderer()->ResetCamera();
    m_cameraSet = true;
  }
  m_lastBuildMs = static_cast<double>(timer.nsecsElapsed()) / 1e6;
  m_view->update();
}

}  // namespace fl::ui
