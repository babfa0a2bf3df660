#include "window.h"

#include <GLFW/glfw3.h>

#include <cstdlib>

#include "gi/errors.h"

namespace {

[[noreturn]] void noDisplay(const std::string& why) {
  throw gi::Error(gi::ErrorKind::Unsupported, "", "no display available: " + why);
}

std::string glfwReason() {
  const char* description = nullptr;
  glfwGetError(&description);
  return description ? description : "unknown GLFW error";
}

}  // namespace

AppWindow::AppWindow(uint32_t width, uint32_t height, const std::string& title) {
  // Checked first: without either variable GLFW's own message is less clear.
  if (!std::getenv("DISPLAY") && !std::getenv("WAYLAND_DISPLAY"))
    noDisplay("neither DISPLAY nor WAYLAND_DISPLAY is set");
  if (!glfwInit()) noDisplay("glfwInit failed: " + glfwReason());
  if (!glfwVulkanSupported()) {
    glfwTerminate();
    noDisplay("GLFW found no Vulkan loader with surface support");
  }
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);  // Vulkan draws, not OpenGL
  window_ = glfwCreateWindow(int(width), int(height), title.c_str(), nullptr, nullptr);
  if (!window_) {
    const std::string reason = glfwReason();
    glfwTerminate();
    noDisplay("cannot create a window: " + reason);
  }
}

AppWindow::~AppWindow() {
  glfwDestroyWindow(window_);
  glfwTerminate();
}

std::vector<std::string> AppWindow::instanceExtensions() {
  uint32_t count = 0;
  const char** names = glfwGetRequiredInstanceExtensions(&count);
  return {names, names + count};
}

bool AppWindow::closed() {
  glfwPollEvents();
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  while ((w == 0 || h == 0) && !glfwWindowShouldClose(window_)) {
    glfwWaitEvents();  // minimised: nothing to show, so do not spin
    glfwGetFramebufferSize(window_, &w, &h);
  }
  return glfwWindowShouldClose(window_);
}
