// gi-render --window: frames go through a GLFW swapchain on a virtual X server (Xvfb) without
// validation messages, the window path renders the same image as the headless one, and
// without a display it fails with a one-line message instead of crashing.
#include <gtest/gtest.h>

#include "gi/image_io.h"
#include "process.h"
#include "test_support.h"

namespace gi {
namespace {

const std::string kArgs = " --scene default --width 160 --height 120 --validation";

TEST(Window, PresentsFramesUnderXvfb) {
  if (test::runCommand("command -v xvfb-run && command -v Xvfb").exitCode != 0)
    GTEST_SKIP()
        << "xvfb-run/Xvfb not installed (Debian packages xvfb, xauth): skipping window test";
  const std::string dir = test::makeTempDir("window");
  // -a: a free display number, so parallel runs do not collide.
  auto r = test::runCommand("xvfb-run -a -s '-screen 0 320x240x24' " + test::binPath("gi-render") +
                            kArgs + " --window --frames 3 --out " + dir + "/window.png");
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_EQ(r.output.find("validation"), std::string::npos) << r.output;

  auto headless =
      test::runCommand(test::binPath("gi-render") + kArgs + " --out " + dir + "/headless.png");
  ASSERT_EQ(headless.exitCode, 0) << headless.output;
  EXPECT_EQ(readPng(dir + "/window.png").pixels, readPng(dir + "/headless.png").pixels)
      << "presenting must not change what is rendered";
}

TEST(Window, WithoutDisplayFailsWithMessage) {
  auto r = test::runCommand("env -u DISPLAY -u WAYLAND_DISPLAY " + test::binPath("gi-render") +
                            kArgs + " --window --frames 1");
  EXPECT_EQ(r.exitCode, 1) << r.output;  // a clean error exit, not a crash (signal: -1)
  EXPECT_NE(r.output.find("no display available: "), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find('\n'), r.output.size() - 1) << "expected one line:\n" << r.output;
}

}  // namespace
}  // namespace gi
