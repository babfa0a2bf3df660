#include "input_queue.h"

#include <GLFW/glfw3.h>
#include <imgui.h>

namespace demo {

InputQueue::InputQueue(GLFWwindow* window) : window_(window) {
  glfwSetWindowUserPointer(window, this);
  glfwGetCursorPos(window, &x_, &y_);
  glfwSetKeyCallback(window, [](GLFWwindow* w, int key, int, int action, int) {
    if (action != GLFW_REPEAT)
      of(w)->events_.push_back({Event::Type::Key, key, action == GLFW_PRESS, 0, 0, 0});
  });
  glfwSetCharCallback(window, [](GLFWwindow* w, unsigned c) {
    of(w)->events_.push_back({Event::Type::Char, 0, false, 0, 0, c});
  });
  glfwSetMouseButtonCallback(window, [](GLFWwindow* w, int button, int action, int) {
    of(w)->events_.push_back({Event::Type::Button, button, action == GLFW_PRESS, 0, 0, 0});
  });
  glfwSetCursorPosCallback(window, [](GLFWwindow* w, double x, double y) {
    of(w)->events_.push_back({Event::Type::Cursor, 0, false, x, y, 0});
  });
  glfwSetScrollCallback(window, [](GLFWwindow* w, double dx, double dy) {
    of(w)->events_.push_back({Event::Type::Scroll, 0, false, dx, dy, 0});
  });
}

InputQueue::~InputQueue() {
  glfwSetKeyCallback(window_, nullptr);
  glfwSetCharCallback(window_, nullptr);
  glfwSetMouseButtonCallback(window_, nullptr);
  glfwSetCursorPosCallback(window_, nullptr);
  glfwSetScrollCallback(window_, nullptr);
  glfwSetWindowUserPointer(window_, nullptr);
}

InputQueue* InputQueue::of(GLFWwindow* window) {
  return static_cast<InputQueue*>(glfwGetWindowUserPointer(window));
}

void InputQueue::apply(ImGuiIO& io) {
  std::array<bool, 512> keyChanged{};
  std::array<bool, 8> buttonChanged{};
  bool buttonThisFrame = false;
  while (!events_.empty()) {
    const Event& e = events_.front();
    if (e.type == Event::Type::Key && e.code >= 0 && e.code < int(keys_.size())) {
      if (keyChanged[size_t(e.code)] && keys_[size_t(e.code)] != e.down) break;
      keyChanged[size_t(e.code)] = true;
      keys_[size_t(e.code)] = e.down;
    } else if (e.type == Event::Type::Button && e.code >= 0 && e.code < int(buttons_.size())) {
      if (buttonChanged[size_t(e.code)] && buttons_[size_t(e.code)] != e.down) break;
      buttonChanged[size_t(e.code)] = true;
      buttons_[size_t(e.code)] = e.down;
      buttonThisFrame = true;
    } else if (e.type == Event::Type::Cursor) {
      if (buttonThisFrame) break;  // the pointer moved after a click: that is the next frame
      x_ = e.x;
      y_ = e.y;
    } else if (e.type == Event::Type::Char) {
      io.AddInputCharacter(e.codepoint);
    } else if (e.type == Event::Type::Scroll) {
      io.MouseWheelH += float(e.x);
      io.MouseWheel += float(e.y);
    }
    events_.pop_front();
  }
}

void InputQueue::writeTo(ImGuiIO& io) const {
  for (size_t k = 0; k < keys_.size() && k < sizeof(io.KeysDown) / sizeof(io.KeysDown[0]); ++k)
    io.KeysDown[k] = keys_[k];
  io.KeyCtrl = keys_[GLFW_KEY_LEFT_CONTROL] || keys_[GLFW_KEY_RIGHT_CONTROL];
  io.KeyShift = keys_[GLFW_KEY_LEFT_SHIFT] || keys_[GLFW_KEY_RIGHT_SHIFT];
  io.KeyAlt = keys_[GLFW_KEY_LEFT_ALT] || keys_[GLFW_KEY_RIGHT_ALT];
  io.KeySuper = keys_[GLFW_KEY_LEFT_SUPER] || keys_[GLFW_KEY_RIGHT_SUPER];
  for (size_t b = 0; b < buttons_.size() && b < sizeof(io.MouseDown) / sizeof(io.MouseDown[0]); ++b)
    io.MouseDown[b] = buttons_[b];
  io.MousePos = ImVec2(float(x_), float(y_));
}

bool InputQueue::keyDown(int key) const {
  return key >= 0 && key < int(keys_.size()) && keys_[size_t(key)];
}

bool InputQueue::buttonDown(int button) const {
  return button >= 0 && button < int(buttons_.size()) && buttons_[size_t(button)];
}

}  // namespace demo
