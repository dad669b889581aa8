/*
 * VtkRenderWidget: embeds a VTK render window inside a Qt6 QOpenGLWidget and
 * forwards mouse/wheel input to a VTK trackball-camera interactor. It is the
 * single place where FabricLab's 3D views meet Qt.
 *
 * Why not QVTKOpenGLNativeWidget: Debian's VTK Qt module (VTK::GUISupportQt,
 * libvtk9-qt-dev) is built against Qt5; linking it into our Qt6 app would
 * load both Qt majors into one process. So we drive a
 * vtkGenericOpenGLRenderWindow on Qt's context ourselves: VTK renders into
 * its own FBO and blits into the QOpenGLWidget's FBO during paintGL().
 *
 * Rules for callers:
 *  - call VtkRenderWidget::setDefaultSurfaceFormat() before QApplication;
 *  - after changing the scene call update() (not renderWindow()->Render():
 *    VTK may only render inside paintGL, when Qt's context and FBO are bound;
 *    outside of it the render window is marked not ready and Render() is a
 *    no-op).
 */
#pragma once

#include <QImage>
#include <QMetaObject>
#include <QOpenGLWidget>
#include <QString>

#include <vtkSmartPointer.h>

class vtkGenericOpenGLRenderWindow;
class vtkGenericRenderWindowInteractor;
class vtkInteractorStyleTrackballCamera;
class vtkRenderer;
class vtkCallbackCommand;
class vtkObject;

class QMouseEvent;
class QWheelEvent;

namespace fl::ui {

class VtkRenderWidget : public QOpenGLWidget
{
    Q_OBJECT

public:
    explicit VtkRenderWidget(QWidget* parent = nullptr);
    ~VtkRenderWidget() override;

    VtkRenderWidget(const VtkRenderWidget&) = delete;
    VtkRenderWidget& operator=(const VtkRenderWidget&) = delete;

    // Created in the constructor, so actors can be added before the GL
    // context exists.
    vtkRenderer* renderer() const;
    vtkGenericOpenGLRenderWindow* renderWindow() const;

    // Renders a fresh frame into the widget's framebuffer and returns it.
    // Returns a null image if no GL context could be created.
    QImage grabImage();
    bool saveScreenshot(const QString& path);

    // Fits the camera to all visible props and schedules a repaint.
    void resetCamera();

    // Must be called before QApplication is constructed: VTK 9.1 needs an
    // OpenGL >= 3.2 core context, and Qt picks the format at context creation.
    static void setDefaultSurfaceFormat();

signals:
    // Wall-clock time of the VTK render inside paintGL(), in milliseconds.
    void frameRendered(double milliseconds);

protected:
    void initializeGL() override;
    void resizeGL(int w, int h) override;
    void paintGL() override;

    void mousePressEvent(QMouseEvent* event) override;
    void mouseDoubleClickEvent(QMouseEvent* event) override;
    void mouseReleaseEvent(QMouseEvent* event) override;
    void mouseMoveEvent(QMouseEvent* event) override;
    void wheelEvent(QWheelEvent* event) override;

private:
    void releaseGraphicsResources();
    void updateVtkSize();
    void setEventInformation(QMouseEvent* event, int repeatCount);
    void forwardButtonEvent(QMouseEvent* event, bool press, int repeatCount);

    static void onVtkContextEvent(vtkObject* caller, unsigned long eventId,
                                  void* clientData, void* callData);

    vtkSmartPointer<vtkGenericOpenGLRenderWindow> m_renderWindow;
    vtkSmartPointer<vtkRenderer> m_renderer;
    vtkSmartPointer<vtkGenericRenderWindowInteractor> m_interactor;
    vtkSmartPointer<vtkInteractorStyleTrackballCamera> m_interactorStyle;
    vtkSmartPointer<vtkCallbackCommand> m_contextCallback;

    QMetaObject::Connection m_contextDestroyedConnection;
    bool m_glInitialized = false;
    int m_wheelAccumulator = 0; // angleDelta units, 120 == one notch
};

} // namespace fl::ui
