// The walking camera of gi-demo: WASD moves in the horizontal plane (Q/E down/up), the mouse
// turns it (yaw, pitch), Shift runs and Ctrl creeps; the eye never goes below a floor height
// plus a margin. Input comes as a CameraInput, filled from the keyboard and mouse or from a
// script, so both drive the same code.
#pragma once

#include <glm/glm.hpp>

#include "gi/scene.h"

namespace demo {

struct CameraInput {
  float forward = 0, right = 0, up = 0;  // each in [-1, 1]
  bool fast = false, slow = false;
  float lookX = 0, lookY = 0;  // mouse movement in pixels (right, down)
};

class FreeCamera {
 public:
  // Starts where `start` looks from, in the same direction.
  explicit FreeCamera(const gi::CameraView& start, float floorHeight);

  // Advances by `dt` seconds; true when the camera moved or turned.
  bool update(const CameraInput& input, float dt);
  void place(const glm::vec3& position, float yawDeg, float pitchDeg);
  gi::CameraView view() const;  // proj is left for the renderer (aspect)

  glm::vec3 position() const { return position_; }
  float yawDeg() const;
  float pitchDeg() const;
  float speed = 2.0f;                        // metres per second
  float sensitivity = 0.15f;                 // degrees per pixel
  static constexpr float kEyeMargin = 0.3f;  // the eye stays this far above the floor
  float floorHeight;

 private:
  glm::vec3 forward() const;
  glm::vec3 position_{0.0f};
  float yaw_ = 0, pitch_ = 0;  // radians; yaw 0 looks down -z
  float znear_, zfar_, yfov_;
};

}  // namespace demo
