// The scene on the GPU, as a service for effects: its (deformed) vertex, index, instance and
// material buffers for compute work, and draws of the whole scene from any view into an
// effect's own attachments: depth only, the G-buffer set, or a reflective shadow map.
//
// Views: perspective, orthographic, the six faces of a cube (six perspective views with their
// own viewports) and a paraboloid hemisphere (Brabec et al.: the hemisphere around the view's
// -z axis maps to the unit disk; depth is the radial distance, reverse-Z between near and far).
// Image orientation: perspective views (perspectiveReverseZ) put view-space +y at the top of
// the image like the main camera; orthographic views and paraboloid disks keep +y at the
// bottom (texel row increases with +y). Culling is off, so either orientation draws the same.
#pragma once

#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "gi/graph/frame_graph.h"
#include "gi/lights.h"
#include "gi/scene.h"

namespace gi {

// std430 mirrors of `Instance` (common.glsl) and `Material` (gbuffer.frag).
struct GpuInstance {
  glm::mat4 model, prevModel;
  glm::mat4 normalMatrix;  // cofactor of the model's 3x3: finite even for singular transforms
  glm::uvec4 material;     // x: material index, y: first vertex of its (deformed) vertices
};
struct GpuMaterial {
  glm::vec4 baseColor;  // linear rgba
  glm::vec4 emission;   // rgb radiance
  glm::vec4 params;     // roughness, metallic, base-colour texture index (-1 none), 0
};
static_assert(sizeof(GpuInstance) == 3 * sizeof(glm::mat4) + sizeof(glm::uvec4));
static_assert(sizeof(GpuMaterial) == 3 * sizeof(glm::vec4));

// One indexed draw of one mesh instance (vertexOffset already points at deformed copies).
struct SceneDrawItem {
  uint32_t firstIndex = 0, indexCount = 0;
  int32_t vertexOffset = 0;
  uint32_t instance = 0, material = 0;
};

enum class Projection { Perspective, Orthographic, Paraboloid };

struct SceneView {
  glm::mat4 view{1.0f};  // world -> view space (looking down -z)
  glm::mat4 proj{1.0f};  // view -> clip, reverse-Z (unused for Paraboloid)
  Projection projection = Projection::Perspective;
  float znear = 0.05f, zfar = 100.0f;  // Paraboloid: the radial depth range
  VkRect2D viewport{};                 // region of the targets drawn into (0x0: all of them)

  static SceneView fromCamera(const CameraView& camera);
  static SceneView perspective(const glm::vec3& eye, const glm::vec3& forward, float yfov,
                               float aspect, float znear, float zfar);
  // halfWidth/halfHeight: half the view's size in world units.
  static SceneView orthographic(const glm::vec3& eye, const glm::vec3& forward, float halfWidth,
                                float halfHeight, float znear, float zfar);
  static SceneView paraboloid(const glm::vec3& center, const glm::vec3& axis, float znear,
                              float zfar);
  // +x, -x, +y, -y, +z, -z; 90 degree faces. Set each face's viewport to place it in an atlas.
  static std::array<SceneView, 6> cube(const glm::vec3& center, float znear, float zfar);
};

// What a draw writes: the colour attachments in sceneColorFormats() order, plus D32 depth.
enum class SceneOutputs {
  Depth,    // depth only (reverse-Z: 1 at near, cleared 0 = nothing)
  GBuffer,  // the packed G-buffer and motion (gi/gbuffer.h, gbuffer.glsl): the main view's set
  // RGBA32F world position (w 1: geometry), RGBA16F world normal, RGBA32F reflected flux (W)
  ReflectiveShadowMap,
};
std::vector<VkFormat> sceneColorFormats(SceneOutputs outputs);
inline constexpr VkFormat kSceneDepthFormat = VK_FORMAT_D32_SFLOAT;
// Bytes between the DrawView records (scene_view.glsl, std140) drawDepthFromBuffer reads: a
// multiple of every device's minUniformBufferOffsetAlignment (at most 256).
inline constexpr VkDeviceSize kDrawViewStride = 256;

struct SceneTargets {
  VkImageView depth = VK_NULL_HANDLE;
  std::vector<VkImageView> colors;  // sceneColorFormats(outputs) order
  VkExtent2D extent{};              // of the attachments
  bool clear = true;                // depth 0 (far), colours 0 before drawing
};

class GpuScene {
 public:
  virtual ~GpuScene() = default;
  virtual VkBuffer vertices() const = 0;  // gi::Vertex; skinned/morphed copies rewritten each frame
  virtual VkBuffer indices() const = 0;   // uint32 triangle lists
  virtual VkBuffer instances() const = 0;  // GpuInstance, current pose
  virtual VkBuffer materials() const = 0;  // GpuMaterial
  virtual const std::vector<SceneDrawItem>& drawItems() const = 0;
  virtual uint64_t triangleCount() const = 0;  // drawn triangles (instances counted)
  // World-space bounds of the posed geometry (a unit box when empty).
  virtual void bounds(glm::vec3& lo, glm::vec3& hi) const = 0;

  // Declares, in a pass's setup, that the pass reads the scene's vertices this frame (orders it
  // after the skinning pass that deforms them). Every pass drawing the scene must call it.
  virtual void declareRead(PassBuilder& builder, BufferUsage usage = BufferUsage::Vertex) const = 0;

  // Record draws of every instance, inside their own dynamic rendering scope. Each view draws
  // into its viewport (a cube's faces, atlas tiles). Perspective and orthographic views skip
  // the instances whose posed bounds lie wholly outside their frustum (CPU culling, the same
  // image: what is skipped would have been clipped away).
  virtual void drawDepth(PassContext& pc, const SceneTargets& targets,
                         std::span<const SceneView> views) = 0;
  // As drawDepth, with view i's DrawView record (scene_view.glsl) read on the GPU from `views`
  // at i x kDrawViewStride bytes and drawn into viewports[i]: views that an earlier pass of the
  // same frame computed (e.g. from light sources it placed) without reading them back. The calling
  // pass declares `views` a Uniform read; a record may clip everything (nothing drawn).
  virtual void drawDepthFromBuffer(PassContext& pc, const SceneTargets& targets, VkBuffer views,
                                   std::span<const VkRect2D> viewports) = 0;
  // The G-buffer set seen through `viewUniforms` (a FrameUniforms buffer: frameUniforms() or
  // an extra view's), exactly as the main G-buffer pass draws it. With `cullWorldToClip` (that
  // view's world -> clip matrix), instances wholly outside its frustum are not drawn.
  virtual void drawGBuffer(PassContext& pc, const SceneTargets& targets, VkBuffer viewUniforms,
                           const glm::mat4* cullWorldToClip = nullptr) = 0;
  // A reflective shadow map (Dachsbacher and Stamminger 2005) of `light` from `view`: per texel
  // the world position and normal of the visible surface and the flux it reflects, albedo x the
  // flux the light sends through the texel (radiance x texel area for a directional light,
  // intensity x texel solid angle x cone and range falloff otherwise), so the flux of a map that
  // sees all the light's output onto a white surface sums to the light's power.
  virtual void drawRsm(PassContext& pc, const SceneTargets& targets, const SceneView& view,
                       const LightInfo& light) = 0;
  // Layered depth (depth peeling, Everitt 2001): as drawDepth, keeping only the fragments
  // strictly behind `previous` at their pixel (reverse-Z depth below it by more than a relative
  // 2^-20, so the layer before is never drawn again; sky 0 keeps nothing), so that drawing layer
  // k+1 against layer k gives the nearest surface behind it. `previous` is a D32 view of the
  // layer before (the main "depth", or the last peeled layer) with the targets' extent, drawn
  // with the same views, read with texelFetch; the pass declares it a Sampled read.
  virtual void drawDepthPeeled(PassContext& pc, const SceneTargets& targets,
                               std::span<const SceneView> views, VkImageView previous) = 0;
};

}  // namespace gi
