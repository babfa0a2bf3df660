#include "free_camera.h"

#include <algorithm>
#include <cmath>

namespace demo {

namespace {
constexpr float kMaxPitch = glm::radians(89.0f);  // lookAlong flips its up vector at the pole
}

FreeCamera::FreeCamera(const gi::CameraView& start, float floor)
    : floorHeight(floor), znear_(start.znear), zfar_(start.zfar), yfov_(start.yfov) {
  position_ = start.position;
  // The view matrix's third row is the camera's +z axis in world space; it looks down -z.
  const glm::vec3 f = -glm::vec3(start.view[0][2], start.view[1][2], start.view[2][2]);
  yaw_ = std::atan2(f.x, -f.z);
  pitch_ = std::asin(std::clamp(f.y, -1.0f, 1.0f));
  pitch_ = std::clamp(pitch_, -kMaxPitch, kMaxPitch);
  position_.y = std::max(position_.y, floorHeight + kEyeMargin);
}

glm::vec3 FreeCamera::forward() const {
  return {std::sin(yaw_) * std::cos(pitch_), std::sin(pitch_), -std::cos(yaw_) * std::cos(pitch_)};
}

float FreeCamera::yawDeg() const {
  return glm::degrees(yaw_);
}
float FreeCamera::pitchDeg() const {
  return glm::degrees(pitch_);
}

void FreeCamera::place(const glm::vec3& position, float yawDeg, float pitchDeg) {
  position_ = position;
  position_.y = std::max(position_.y, floorHeight + kEyeMargin);
  yaw_ = glm::radians(yawDeg);
  pitch_ = std::clamp(glm::radians(pitchDeg), -kMaxPitch, kMaxPitch);
}

bool FreeCamera::update(const CameraInput& in, float dt) {
  const glm::vec3 before = position_;
  const float yawBefore = yaw_, pitchBefore = pitch_;
  yaw_ += glm::radians(in.lookX * sensitivity);
  pitch_ = std::clamp(pitch_ - glm::radians(in.lookY * sensitivity), -kMaxPitch, kMaxPitch);
  // Walking stays horizontal whatever the pitch; Q/E (up) is vertical.
  const glm::vec3 ahead{std::sin(yaw_), 0.0f, -std::cos(yaw_)};
  const glm::vec3 right{std::cos(yaw_), 0.0f, std::sin(yaw_)};
  glm::vec3 move = ahead * in.forward + right * in.right + glm::vec3(0, 1, 0) * in.up;
  if (glm::length(move) > 1.0f) move = glm::normalize(move);
  const float v = speed * (in.fast ? 4.0f : 1.0f) * (in.slow ? 0.25f : 1.0f);
  position_ += move * v * std::max(dt, 0.0f);
  position_.y = std::max(position_.y, floorHeight + kEyeMargin);  // collision with the floor
  return position_ != before || yaw_ != yawBefore || pitch_ != pitchBefore;
}

gi::CameraView FreeCamera::view() const {
  gi::CameraView v;
  v.view = gi::lookAlong(position_, forward());
  v.position = position_;
  v.znear = znear_;
  v.zfar = zfar_;
  v.yfov = yfov_;
  return v;
}

}  // namespace demo
