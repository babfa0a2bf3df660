// GLFW input as a queue of events, replayed in order to Dear ImGui and the camera, one change of
// each key or mouse button per frame. Debian's Dear ImGui (1.86) keeps the keys' state, not
// events: at a few frames per second a quick tap (press and release between two frames) was
// lost, and a click landed where the pointer was a frame later. Here the tap is held for one
// frame and released on the next, and a click is applied at the position the pointer had then.
#pragma once

#include <array>
#include <deque>

struct GLFWwindow;
struct ImGuiIO;

namespace demo {

class InputQueue {
 public:
  // Installs the window's key, character, mouse button, cursor and scroll callbacks (Dear
  // ImGui's GLFW backend must be initialised without its own).
  explicit InputQueue(GLFWwindow* window);
  ~InputQueue();
  InputQueue(const InputQueue&) = delete;
  InputQueue& operator=(const InputQueue&) = delete;

  // At the start of a frame: applies the queued events in order up to the first that would
  // change a key or button a second time this frame (the rest wait for the next frame); typed
  // characters and scrolling go to `io` as they come.
  void apply(ImGuiIO& io);
  // The keys, buttons and pointer to `io`: after ImGui_ImplGlfw_NewFrame() (which reads the
  // devices' current state into it) and before ImGui::NewFrame().
  void writeTo(ImGuiIO& io) const;
  // The state after the last apply(): what the camera controller reads.
  bool keyDown(int key) const;
  bool buttonDown(int button) const;
  double cursorX() const { return x_; }
  double cursorY() const { return y_; }

 private:
  struct Event {
    enum class Type { Key, Char, Button, Cursor, Scroll } type;
    int code = 0;         // key or button
    bool down = false;    // pressed (or repeated) / released
    double x = 0, y = 0;  // cursor position or scroll offsets
    unsigned codepoint = 0;
  };
  static InputQueue* of(GLFWwindow* window);

  GLFWwindow* window_;
  std::deque<Event> events_;
  std::array<bool, 512> keys_{};
  std::array<bool, 8> buttons_{};
  double x_ = 0, y_ = 0;
};

}  // namespace demo
