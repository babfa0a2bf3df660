// The built-in scene (a Cornell-box-like room with a bouncing sphere) and the defaults added to
// bare model files.
#include <glm/gtc/matrix_transform.hpp>

#include "gi/scene_io.h"
#include "scene_io_util.h"

namespace gi {
namespace {

int addMaterial(Scene& s, const std::string& name, glm::vec3 color, float roughness = 0.9f,
                glm::vec3 emission = glm::vec3(0.0f)) {
  Material m;
  m.name = name;
  m.baseColor = glm::vec4(color, 1.0f);
  m.roughness = roughness;
  m.emission = emission;
  s.materials.push_back(m);
  return static_cast<int>(s.materials.size()) - 1;
}

// Adds `mesh` with `material` under a new root node with transform `local`.
int addMeshNode(Scene& s, const std::string& name, Mesh mesh, int material,
                const glm::mat4& local) {
  mesh.name = name;
  mesh.material = static_cast<uint32_t>(material);
  s.meshes.push_back(std::move(mesh));
  int node = s.addNode(name, local);
  s.nodes[node].meshes.push_back(static_cast<int>(s.meshes.size()) - 1);
  return node;
}

glm::mat4 translate(glm::vec3 t) {
  return glm::translate(glm::mat4(1.0f), t);
}
glm::mat4 rotate(float degrees, glm::vec3 axis) {
  return glm::rotate(glm::mat4(1.0f), glm::radians(degrees), axis);
}

// The moving object: `node` (at rest at `rest`, given by translate(rest)) bounces straight up
// and back every kBouncePeriod seconds on a parabola y = rest.y + 4 h u (1 - u), u = t / period,
// h = kBounceHeight: one CUBICSPLINE segment whose tangents +-4h/period make it exactly that
// parabola. At t = 0 (and every whole period) it is exactly at `rest`, so still images of the
// scene at time 0 do not change.
constexpr float kBouncePeriod = 2.0f;
constexpr float kBounceHeight = 0.3f;

void addBounce(Scene& s, int node, const glm::vec3& rest) {
  Node& n = s.nodes[node];
  n.hasTRS = true;
  n.translation = rest;
  const float slope = 4.0f * kBounceHeight / kBouncePeriod;  // dy/dt at take-off
  AnimationSampler up;
  up.interpolation = Interpolation::CubicSpline;
  up.components = 3;
  up.times = {0.0f, kBouncePeriod};
  // Per key: in-tangent, value, out-tangent.
  const glm::vec3 none(0.0f), takeOff(0.0f, slope, 0.0f), landing(0.0f, -slope, 0.0f);
  for (const glm::vec3& v : {none, rest, takeOff, landing, rest, none})
    up.values.insert(up.values.end(), {v.x, v.y, v.z});
  AnimationClip clip;
  clip.name = "sphere bounce";
  clip.samplers.push_back(std::move(up));
  clip.channels.push_back({0, node, AnimationPath::Translation});
  clip.duration = kBouncePeriod;
  s.animations.push_back(std::move(clip));
}

}  // namespace

Scene makeDefaultScene() {
  Scene s;
  s.sourcePath = "default";
  // Albedos of the classic Cornell box (linear).
  const int white = addMaterial(s, "white", {0.73f, 0.73f, 0.73f});
  const int red = addMaterial(s, "red", {0.63f, 0.065f, 0.05f});
  const int green = addMaterial(s, "green", {0.14f, 0.45f, 0.091f});
  const int sphere = addMaterial(s, "sphere", {0.25f, 0.4f, 0.8f}, 0.3f);
  const int lamp = addMaterial(s, "light", {1.0f, 1.0f, 1.0f}, 0.9f, {12.0f, 10.8f, 9.0f});

  // Room: x, y, z in [-1, 1], open towards +z where the camera stands. The plane faces +y;
  // each wall is rotated so that it faces into the room.
  const Mesh wall = detail::makePlane(2.0f, 2.0f);
  addMeshNode(s, "floor", wall, white, translate({0, -1, 0}));
  addMeshNode(s, "ceiling", wall, white, translate({0, 1, 0}) * rotate(180, {1, 0, 0}));
  addMeshNode(s, "back wall", wall, white, translate({0, 0, -1}) * rotate(90, {1, 0, 0}));
  addMeshNode(s, "left wall", wall, red, translate({-1, 0, 0}) * rotate(-90, {0, 0, 1}));
  addMeshNode(s, "right wall", wall, green, translate({1, 0, 0}) * rotate(90, {0, 0, 1}));

  // Blocks as in the classic box: a short one front-right, a tall one back-left, turned
  // towards each other; the sphere rests on the short block.
  addMeshNode(s, "short block", detail::makeBox({0.6f, 0.6f, 0.6f}), white,
              translate({0.33f, -0.7f, 0.3f}) * rotate(-17, {0, 1, 0}));
  addMeshNode(s, "tall block", detail::makeBox({0.6f, 1.2f, 0.6f}), white,
              translate({-0.35f, -0.4f, -0.35f}) * rotate(17, {0, 1, 0}));
  const glm::vec3 rest(0.33f, -0.4f + 0.25f, 0.3f);
  const int ball =
      addMeshNode(s, "sphere", detail::makeSphere(0.25f, 32, 16), sphere, translate(rest));
  addBounce(s, ball, rest);

  // Regions scored apart (gi-bench): each face of the room, and the floor around each block
  // (the contact strips, where screen-space methods and the bounce differ most).
  const float e = 0.002f;
  s.regions = {{"floor", {-1, -1 - e, -1}, {1, -1 + e, 1}},
               {"ceiling", {-1, 1 - e, -1}, {1, 1 + e, 1}},
               {"back wall", {-1, -1, -1 - e}, {1, 1, -1 + e}},
               {"red wall", {-1 - e, -1, -1}, {-1 + e, 1, 1}},
               {"green wall", {1 - e, -1, -1}, {1 + e, 1, 1}},
               {"floor by the short block", {-0.22f, -1 - e, -0.25f}, {0.88f, -1 + e, 0.85f}},
               {"floor by the tall block", {-0.9f, -1 - e, -0.9f}, {0.2f, -1 + e, 0.2f}}};

  // Lamp: a small emissive quad just under the ceiling plus a point light below it (the
  // rasteriser's direct lighting comes from the point light; the quad is what is seen).
  addMeshNode(s, "lamp", detail::makePlane(0.5f, 0.4f), lamp,
              translate({0, 0.995f, 0}) * rotate(180, {1, 0, 0}));
  Light light;
  light.name = "ceiling light";
  light.type = LightType::Point;
  light.color = {1.0f, 0.9f, 0.75f};
  light.intensity = 4.0f;
  light.castsShadows = true;
  s.lights.push_back(light);
  s.nodes[s.addNode("ceiling light", translate({0, 0.9f, 0}))].light = 0;

  // Camera on the open side looking down -z (its local forward), framing the opening.
  Camera cam;
  cam.name = "camera";
  cam.yfov = glm::radians(39.3f);
  cam.znear = 0.1f;
  cam.zfar = 20.0f;
  s.cameras.push_back(cam);
  s.activeCameraNode = s.addNode("camera", translate({0, 0, 3.9f}));
  s.nodes[s.activeCameraNode].camera = 0;

  s.environment.kind = Environment::Kind::Sky;
  s.environment.intensity = 0.5f;
  s.updateWorldTransforms();
  return s;
}

void addDefaultCameraAndLight(Scene& scene) {
  scene.updateWorldTransforms();
  glm::vec3 bmin, bmax;
  scene.worldBounds(bmin, bmax);
  const glm::vec3 centre = 0.5f * (bmin + bmax);
  const float radius = std::max(0.5f * glm::length(bmax - bmin), 1e-20f);  // as the framing

  int cameraNode = -1;
  for (size_t i = 0; i < scene.nodes.size() && cameraNode < 0; ++i)
    if (scene.nodes[i].camera >= 0) cameraNode = static_cast<int>(i);
  if (cameraNode < 0) {
    // Aspect 1 frames the bounds for any output at least as wide as it is tall.
    CameraView view = cameraFramingBounds(bmin, bmax, 1.0f);
    Camera cam;
    cam.name = "default camera";
    cam.yfov = view.yfov;
    cam.znear = view.znear;
    cam.zfar = view.zfar;
    scene.cameras.push_back(cam);
    cameraNode = scene.addNode(cam.name, glm::inverse(view.view));  // world = inverse(view)
    scene.nodes[cameraNode].camera = static_cast<int>(scene.cameras.size()) - 1;
  }
  if (scene.activeCameraNode < 0) scene.activeCameraNode = cameraNode;

  if (scene.lights.empty()) {
    // Sun from above and in front (the framing camera's side, +z), shining down and back. A
    // light points along its node's -z axis, so the node looks along the light direction.
    const glm::vec3 dir = glm::normalize(glm::vec3(-0.4f, -1.0f, -0.6f));
    const glm::vec3 pos = centre - dir * (2.0f * radius);
    Light sun;
    sun.name = "default sun";
    sun.type = LightType::Directional;
    sun.color = {1.0f, 0.96f, 0.9f};
    sun.intensity = 3.0f;
    sun.castsShadows = true;
    scene.lights.push_back(sun);
    int node = scene.addNode(sun.name, glm::inverse(glm::lookAt(pos, pos + dir, {0, 1, 0})));
    scene.nodes[node].light = static_cast<int>(scene.lights.size()) - 1;
  }
  scene.updateWorldTransforms();
}

}  // namespace gi
