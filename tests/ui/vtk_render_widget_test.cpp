// Proves VtkRenderWidget really puts VTK pixels into the Qt6 framebuffer
// (the point of not using the Qt5-only QVTKOpenGLNativeWidget) and that mouse
// input reaches the VTK camera. Needs a display: run under xvfb-run.

#include "ui/vtk_render_widget.hpp"

#include <gtest/gtest.h>

#include <QApplication>
#include <QCoreApplication>
#include <QElapsedTimer>
#include <QMouseEvent>
#include <QThread>
#include <QWheelEvent>

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkNew.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkSphereSource.h>

#include <array>
#include <functional>
#include <memory>

namespace {

// One QApplication for the whole binary; gtest_main owns main(), so create it
// from a global environment (set up before the first test, torn down after
// the last one, i.e. while VTK and Qt are still alive).
class QtEnvironment : public ::testing::Environment
{
public:
    void SetUp() override
    {
        fl::ui::VtkRenderWidget::setDefaultSurfaceFormat();
        m_app = std::make_unique<QApplication>(m_argc, m_argv.data());
    }
    void TearDown() override { m_app.reset(); }

private:
    int m_argc = 1;
    char m_arg0[32] = "vtk_render_widget_test";
    std::array<char*, 2> m_argv{m_arg0, nullptr};
    std::unique_ptr<QApplication> m_app;
};

[[maybe_unused]] auto* const g_qtEnvironment =
    ::testing::AddGlobalTestEnvironment(new QtEnvironment);

bool waitUntil(const std::function<bool()>& condition, int timeoutMs = 10000)
{
    QElapsedTimer timer;
    timer.start();
    while (!condition()) {
        if (timer.elapsed() > timeoutMs) {
            return false;
        }
        QCoreApplication::processEvents(QEventLoop::AllEvents, 50);
        QThread::msleep(5);
    }
    return true;
}

struct SphereScene
{
    fl::ui::VtkRenderWidget widget;
    int framesRendered = 0;

    SphereScene()
    {
        vtkNew<vtkSphereSource> sphere;
        sphere->SetThetaResolution(48);
        sphere->SetPhiResolution(48);
        vtkNew<vtkPolyDataMapper> mapper;
        mapper->SetInputConnection(sphere->GetOutputPort());
        vtkNew<vtkActor> actor;
        actor->SetMapper(mapper);
        actor->GetProperty()->SetColor(1.0, 0.0, 0.0);

        // Scene is built before any GL context exists, as real callers do.
        widget.renderer()->AddActor(actor);
        widget.renderer()->SetBackground(0.0, 0.0, 0.0);
        widget.resetCamera();

        QObject::connect(&widget, &fl::ui::VtkRenderWidget::frameRendered,
                         [this](double ms) {
                             EXPECT_GE(ms, 0.0);
                             ++framesRendered;
                         });
        widget.resize(320, 240);
        widget.show();
    }

    bool waitForFrame(int atLeast = 1)
    {
        return waitUntil([&] { return framesRendered >= atLeast; });
    }
};

bool isReddish(QRgb p)
{
    return qRed(p) > 100 && qGreen(p) < 60 && qBlue(p) < 60;
}

bool isBlack(QRgb p)
{
    return qRed(p) < 10 && qGreen(p) < 10 && qBlue(p) < 10;
}

void sendMouse(QWidget& w, QEvent::Type type, QPointF pos, Qt::MouseButton button,
               Qt::MouseButtons buttons)
{
    QMouseEvent event(type, pos, w.mapToGlobal(pos), button, buttons, Qt::NoModifier);
    QCoreApplication::sendEvent(&w, &event);
}

} // namespace

TEST(VtkRenderWidget, RendersRedSphereOnBlackBackground)
{
    SphereScene scene;
    ASSERT_TRUE(scene.waitForFrame()) << "widget never painted";

    const QImage image = scene.widget.grabImage();
    ASSERT_FALSE(image.isNull());
    const QSize expected = QSize(320, 240) * scene.widget.devicePixelRatioF();
    ASSERT_EQ(image.size(), expected);

    int reddish = 0;
    for (int y = 0; y < image.height(); ++y) {
        for (int x = 0; x < image.width(); ++x) {
            reddish += isReddish(image.pixel(x, y)) ? 1 : 0;
        }
    }
    // A reset camera frames the unit sphere to roughly half the viewport
    // height; demand at least ~5% of the pixels so a stray line cannot pass.
    EXPECT_GT(reddish, image.width() * image.height() / 20) << "reddish pixels: " << reddish;

    const int w = image.width() - 1;
    const int h = image.height() - 1;
    for (const QPoint corner : {QPoint(0, 0), QPoint(w, 0), QPoint(0, h), QPoint(w, h)}) {
        const QRgb p = image.pixel(corner);
        EXPECT_TRUE(isBlack(p)) << "corner (" << corner.x() << "," << corner.y()
                                << ") = " << qRed(p) << "," << qGreen(p) << "," << qBlue(p);
    }

    // The centre must be sphere, not background: catches a blit into the
    // wrong framebuffer that would leave only the clear colour.
    EXPECT_TRUE(isReddish(image.pixel(image.width() / 2, image.height() / 2)));
}

TEST(VtkRenderWidget, MouseDragRotatesCamera)
{
    SphereScene scene;
    ASSERT_TRUE(scene.waitForFrame());

    std::array<double, 3> before{};
    scene.widget.renderer()->GetActiveCamera()->GetPosition(before.data());

    const int framesBefore = scene.framesRendered;
    sendMouse(scene.widget, QEvent::MouseButtonPress, {160, 120}, Qt::LeftButton, Qt::LeftButton);
    for (int i = 1; i <= 10; ++i) {
        sendMouse(scene.widget, QEvent::MouseMove, {160.0 + 8.0 * i, 120.0 + 3.0 * i},
                  Qt::NoButton, Qt::LeftButton);
    }
    sendMouse(scene.widget, QEvent::MouseButtonRelease, {240, 150}, Qt::LeftButton, Qt::NoButton);

    std::array<double, 3> after{};
    scene.widget.renderer()->GetActiveCamera()->GetPosition(after.data());
    const double moved = std::hypot(after[0] - before[0], after[1] - before[1], after[2] - before[2]);
    EXPECT_GT(moved, 1e-3) << "camera did not move";

    // Interaction must schedule a repaint rather than render synchronously.
    EXPECT_TRUE(scene.waitForFrame(framesBefore + 1));
}

TEST(VtkRenderWidget, WheelZoomsCamera)
{
    SphereScene scene;
    ASSERT_TRUE(scene.waitForFrame());

    vtkCamera* camera = scene.widget.renderer()->GetActiveCamera();
    const double distanceBefore = camera->GetDistance();

    const QPointF pos(160, 120);
    QWheelEvent wheel(pos, scene.widget.mapToGlobal(pos), QPoint(), QPoint(0, 120), Qt::NoButton,
                      Qt::NoModifier, Qt::NoScrollPhase, false);
    QCoreApplication::sendEvent(&scene.widget, &wheel);

    EXPECT_LT(camera->GetDistance(), distanceBefore) << "wheel forward should zoom in";
}
