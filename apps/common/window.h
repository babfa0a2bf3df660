// The window of `gi-render --window` and gi-demo: opens it with GLFW (or says why there is no
// display) and tells the frame loop when the user has closed it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

struct GLFWwindow;

class AppWindow {
 public:
  // Throws gi::Error(Unsupported, "no display available: ...") when no window can be opened.
  AppWindow(uint32_t width, uint32_t height, const std::string& title);
  ~AppWindow();
  AppWindow(const AppWindow&) = delete;
  AppWindow& operator=(const AppWindow&) = delete;

  GLFWwindow* handle() const { return window_; }
  // Instance extensions a Vulkan surface for this window needs (vk::ContextOptions).
  static std::vector<std::string> instanceExtensions();
  // Handles pending events; true once the user asked to close. Sleeps while minimised.
  bool closed();

 private:
  GLFWwindow* window_ = nullptr;
};
