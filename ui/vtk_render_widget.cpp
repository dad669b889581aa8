#include "vtk_render_widget.hpp"

#include <QElapsedTimer>
#include <QMouseEvent>
#include <QOpenGLContext>
#include <QOpenGLFunctions>
#include <QSurfaceFormat>
#include <QWheelEvent>

#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkGenericRenderWindowInteractor.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkOpenGLState.h>
#include <vtkRenderer.h>

#include <algorithm>
#include <cmath>

namespace fl::ui {

VtkRenderWidget::VtkRenderWidget(QWidget* parent)
    : QOpenGLWidget(parent)
    , m_renderWindow(vtkSmartPointer<vtkGenericOpenGLRenderWindow>::New())
    , m_renderer(vtkSmartPointer<vtkRenderer>::New())
    , m_interactor(vtkSmartPointer<vtkGenericRenderWindowInteractor>::New())
    , m_interactorStyle(vtkSmartPointer<vtkInteractorStyleTrackballCamera>::New())
    , m_contextCallback(vtkSmartPointer<vtkCallbackCommand>::New())
{
    // Without an opaque background alpha the (alpha-less) Qt framebuffer is
    // composited as translucent and the view shows up grey.
    m_renderer->SetBackgroundAlpha(1.0);

    // Qt owns the context; VTK must never create or swap one itself.
    m_renderWindow->SetOwnContext(false);
    m_renderWindow->SetFrameBlitModeToBlitToCurrent();
    // VTK's default 8x multisampled offscreen buffer costs 8x the fragment work; with Mesa's software
    // rasteriser (no GPU, CI, Xvfb) that made a 4000-sphere frame take over half a second.
    m_renderWindow->SetMultiSamples(0);
    // VTK may only draw from paintGL(); see the header for why.
    m_renderWindow->SetReadyForRendering(false);

    // VTK asks "make current"/"is current" when it needs GL outside a
    // render (e.g. releasing resources), so route those to Qt's context.
    m_contextCallback->SetCallback(&VtkRenderWidget::onVtkContextEvent);
    m_contextCallback->SetClientData(this);
    m_renderWindow->AddObserver(vtkCommand::WindowMakeCurrentEvent, m_contextCallback);
    m_renderWindow->AddObserver(vtkCommand::WindowIsCurrentEvent, m_contextCallback);

    m_interactor->SetInteractorStyle(m_interactorStyle);
    m_interactor->SetRenderWindow(m_renderWindow);
    // The interactor style would call Render() itself after every camera
    // change; we schedule a Qt repaint instead so rendering stays in paintGL.
    m_interactor->EnableRenderOff();
    m_interactor->Initialize();

    // Button-down only: VTK styles ignore plain hover moves anyway.
    setMouseTracking(false);
    setFocusPolicy(Qt::StrongFocus);
}

VtkRenderWidget::~VtkRenderWidget()
{
    releaseGraphicsResources();
    // The QOpenGLWidget base destroys the context after we are gone; do not
    // let that signal reach a half-destroyed object.
    QObject::disconnect(m_contextDestroyedConnection);
    // VTK's own destructor calls Finalize() again; with the observers gone it
    // cannot call back into this widget.
    m_renderWindow->RemoveObserver(m_contextCallback);
}

vtkRenderer* VtkRenderWidget::renderer() const
{
    return m_renderer;
}

vtkGenericOpenGLRenderWindow* VtkRenderWidget::renderWindow() const
{
    return m_renderWindow;
}

QImage VtkRenderWidget::grabImage()
{
    // grabFramebuffer() runs paintGL() into the widget FBO and reads it back,
    // so the result always contains an up-to-date VTK frame.
    return grabFramebuffer();
}

bool VtkRenderWidget::saveScreenshot(const QString& path)
{
    const QImage image = grabImage();
    return !image.isNull() && image.save(path);
}

void VtkRenderWidget::resetCamera()
{
    m_renderer->ResetCamera();
    update();
}

void VtkRenderWidget::setDefaultSurfaceFormat()
{
    QSurfaceFormat format;
    format.setRenderableType(QSurfaceFormat::OpenGL);
    // VTK 9.1's OpenGL2 backend requires >= 3.2 core.
    format.setVersion(3, 2);
    format.setProfile(QSurfaceFormat::CoreProfile);
    format.setDepthBufferSize(24);
    // VTK renders into its own FBO and blits; an alpha channel in Qt's
    // buffer would only make the widget translucent.
    format.setAlphaBufferSize(0);
    QSurfaceFormat::setDefaultFormat(format);
}

void VtkRenderWidget::initializeGL()
{
    // A widget can get a new context (e.g. when reparented to another
    // top-level window); VTK's GPU objects die with the old one.
    QObject::disconnect(m_contextDestroyedConnection);
    m_contextDestroyedConnection = connect(context(), &QOpenGLContext::aboutToBeDestroyed,
                                           this, [this] { releaseGraphicsResources(); });

    m_renderWindow->SetOwnContext(false);
    m_renderWindow->SetFrameBlitModeToBlitToCurrent();
    m_renderWindow->OpenGLInitContext();
    m_renderWindow->SetMapped(1);
    m_renderWindow->SetIsCurrent(true);
    m_renderWindow->AddRenderer(m_renderer); // no-op if already added
    m_glInitialized = true;
    updateVtkSize();
}

void VtkRenderWidget::resizeGL(int /*w*/, int /*h*/)
{
    // Qt passes logical pixels; VTK needs device pixels (HiDPI).
    updateVtkSize();
}

void VtkRenderWidget::paintGL()
{
    if (!m_glInitialized) {
        return;
    }
    updateVtkSize();

    QElapsedTimer timer;
    timer.start();

    m_renderWindow->SetReadyForRendering(true);
    // Qt changed GL state behind VTK's back since the last frame; VTK caches
    // state, so resynchronise its cache before drawing.
    m_renderWindow->GetState()->Reset();
    m_renderWindow->Render();
    m_renderWindow->SetReadyForRendering(false);

    // VTK may leave its own FBO bound; Qt composes from ours.
    context()->functions()->glBindFramebuffer(GL_FRAMEBUFFER, defaultFramebufferObject());

    emit frameRendered(static_cast<double>(timer.nsecsElapsed()) / 1.0e6);
}

void VtkRenderWidget::mousePressEvent(QMouseEvent* event)
{
    forwardButtonEvent(event, true, 0);
}

void VtkRenderWidget::mouseDoubleClickEvent(QMouseEvent* event)
{
    // Qt replaces the second press by a double-click event; VTK expects a
    // press with a repeat count instead.
    forwardButtonEvent(event, true, 1);
}

void VtkRenderWidget::mouseReleaseEvent(QMouseEvent* event)
{
    forwardButtonEvent(event, false, 0);
}

void VtkRenderWidget::mouseMoveEvent(QMouseEvent* event)
{
    setEventInformation(event, 0);
    m_interactor->InvokeEvent(vtkCommand::MouseMoveEvent, nullptr);
    event->accept();
    update();
}

void VtkRenderWidget::wheelEvent(QWheelEvent* event)
{
    // Accumulate so high-resolution wheels/touchpads (small deltas) zoom in
    // whole VTK steps instead of one step per tiny event.
    m_wheelAccumulator += event->angleDelta().y();
    const int steps = m_wheelAccumulator / 120;
    if (steps == 0) {
        event->accept();
        return;
    }
    m_wheelAccumulator -= steps * 120;

    const qreal dpr = devicePixelRatioF();
    const QPointF pos = event->position() * dpr;
    const Qt::KeyboardModifiers mods = event->modifiers();
    m_interactor->SetEventInformationFlipY(static_cast<int>(std::lround(pos.x())),
                                           static_cast<int>(std::lround(pos.y())),
                                           (mods & Qt::ControlModifier) ? 1 : 0,
                                           (mods & Qt::ShiftModifier) ? 1 : 0);
    m_interactor->SetAltKey((mods & Qt::AltModifier) ? 1 : 0);
    const unsigned long vtkEvent =
        steps > 0 ? vtkCommand::MouseWheelForwardEvent : vtkCommand::MouseWheelBackwardEvent;
    for (int i = 0; i < std::abs(steps); ++i) {
        m_interactor->InvokeEvent(vtkEvent, nullptr);
    }
    event->accept();
    update();
}

void VtkRenderWidget::releaseGraphicsResources()
{
    if (!m_glInitialized) {
        return;
    }
    m_glInitialized = false;
    // Deleting VTK's textures/buffers requires our context to be current.
    makeCurrent();
    m_renderWindow->Finalize();
    m_renderWindow->SetReadyForRendering(false);
    doneCurrent();
}

void VtkRenderWidget::updateVtkSize()
{
    const qreal dpr = devicePixelRatioF();
    const int w = std::max(1, static_cast<int>(std::lround(width() * dpr)));
    const int h = std::max(1, static_cast<int>(std::lround(height() * dpr)));
    m_renderWindow->SetSize(w, h);
    // The interactor flips Y using its own copy of the size.
    m_interactor->SetSize(w, h);
}

void VtkRenderWidget::setEventInformation(QMouseEvent* event, int repeatCount)
{
    updateVtkSize();
    const qreal dpr = devicePixelRatioF();
    const QPointF pos = event->position() * dpr;
    const Qt::KeyboardModifiers mods = event->modifiers();
    m_interactor->SetEventInformationFlipY(static_cast<int>(std::lround(pos.x())),
                                           static_cast<int>(std::lround(pos.y())),
                                           (mods & Qt::ControlModifier) ? 1 : 0,
                                           (mods & Qt::ShiftModifier) ? 1 : 0, 0,
                                           repeatCount);
    m_interactor->SetAltKey((mods & Qt::AltModifier) ? 1 : 0);
}

void VtkRenderWidget::forwardButtonEvent(QMouseEvent* event, bool press, int repeatCount)
{
    unsigned long vtkEvent = vtkCommand::NoEvent;
    switch (event->button()) {
    case Qt::LeftButton:
        vtkEvent = press ? vtkCommand::LeftButtonPressEvent : vtkCommand::LeftButtonReleaseEvent;
        break;
    case Qt::MiddleButton:
        vtkEvent = press ? vtkCommand::MiddleButtonPressEvent : vtkCommand::MiddleButtonReleaseEvent;
        break;
    case Qt::RightButton:
        vtkEvent = press ? vtkCommand::RightButtonPressEvent : vtkCommand::RightButtonReleaseEvent;
        break;
    default:
        // Back/forward etc.: let Qt propagate them to the parent.
        event->ignore();
        return;
    }
    setEventInformation(event, repeatCount);
    m_interactor->InvokeEvent(vtkEvent, nullptr);
    event->accept();
    update();
}

void VtkRenderWidget::onVtkContextEvent(vtkObject* /*caller*/, unsigned long eventId,
                                        void* clientData, void* callData)
{
    auto* self = static_cast<VtkRenderWidget*>(clientData);
    QOpenGLContext* ctx = self->context();
    const bool isCurrent = ctx != nullptr && QOpenGLContext::currentContext() == ctx;

    if (eventId == vtkCommand::WindowMakeCurrentEvent) {
        // Inside paintGL the context is already current with Qt's FBO bound;
        // calling makeCurrent() again would rebind it under VTK's feet.
        if (!isCurrent && ctx != nullptr) {
            self->makeCurrent();
        }
    } else if (eventId == vtkCommand::WindowIsCurrentEvent) {
        if (callData != nullptr) {
            *static_cast<bool*>(callData) = isCurrent;
        }
    }
}

} // namespace fl::ui
