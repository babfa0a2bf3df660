#version 460
// Classic mode: the DrawView record (scene_view.glsl) of each VPL's paraboloid view, from this
// frame's VPL table, for GpuScene::drawDepthFromBuffer -- the same matrix as
// SceneView::paraboloid (glm::lookAt along the VPL normal, up +y or +z when nearly vertical),
// so the classic maps share texels with the ISMs. A VPL without light (position.w 0) gets a
// view that clips every vertex (its tile stays cleared: nothing occludes).
// ORTHO: environment VPLs (ism_env_vpl.comp, direction d to the sky): an orthographic view
// along -d from c + (R + near) d over the scene's bounding sphere (centre c, radius R), the
// basis of ismOrthoTexel (ismBasis(-d)): a tile's texels are the ISM's; reverse-Z from near to
// far, so a stored depth is the distance from that eye plane (the gathering subtracts near).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "ism_common.glsl"
#include "scene_view.glsl"

layout(constant_id = 0) const bool ORTHO = false;
layout(local_size_x = 64) in;
// VPL indices [first, first + count) of the table at binding 2, tiles from firstTile
layout(push_constant) uniform Push { int first; int count; int firstTile; } range;
layout(set = 0, binding = 2, std140) uniform Vpls { Vpl vpls[ISM_VPL_SLOTS]; };
struct Slot {  // gi::kDrawViewStride = 256 bytes
  DrawView view;
  vec4 pad[2];
};
layout(set = 0, binding = 3, std430) writeonly buffer Views { Slot slots[]; };

void main() {
  int k = int(gl_GlobalInvocationID.x);
  if (k >= range.count) return;
  int i = range.first + k, tile = range.firstTile + k;
  Vpl v = vpls[i];
  float near = ism.bias.z, far = ism.bias.w, radius = max(ism.envSphere.w, 1e-30);
  vec3 eye = ORTHO ? ism.envSphere.xyz + (ism.envDepth.x + near) * v.position.xyz : v.position.xyz;
  vec3 f = ORTHO ? safeNormalize(-v.position.xyz, vec3(0.0, -1.0, 0.0))
                 : safeNormalize(v.normal.xyz, vec3(0.0, -1.0, 0.0));
  vec3 up = abs(f.y) > 0.99 ? vec3(0.0, 0.0, 1.0) : vec3(0.0, 1.0, 0.0);
  vec3 s = normalize(cross(f, up));
  vec3 u = cross(s, f);
  mat4 view = mat4(vec4(s.x, u.x, -f.x, 0.0), vec4(s.y, u.y, -f.y, 0.0),
                   vec4(s.z, u.z, -f.z, 0.0), vec4(-dot(s, eye), -dot(u, eye), dot(f, eye), 1.0));
  // Every point at view position (0, 0, 1): behind the hemisphere (clip distance -1).
  if (v.position.w < 0.5) view = mat4(vec4(0.0), vec4(0.0), vec4(0.0), vec4(0.0, 0.0, 1.0, 1.0));
  int res = int(ism.atlas.x), perRow = int(ism.atlas.y);
  DrawView d;
  d.view = view;
  d.proj = mat4(1.0);
  d.params = vec4(2.0, near, far, 0.0);  // paraboloid, near, far
  if (ORTHO) {  // gi::orthoReverseZ(-R, R, -R, R, near, far): z 1 at near, 0 at far
    float depthRange = max(far - near, 1e-30);
    d.proj = mat4(vec4(1.0 / radius, 0.0, 0.0, 0.0), vec4(0.0, 1.0 / radius, 0.0, 0.0),
                  vec4(0.0, 0.0, 1.0 / depthRange, 0.0),
                  vec4(0.0, 0.0, 1.0 + near / depthRange, 1.0));
    d.params.x = 1.0;
  }
  d.lightPosType = vec4(0.0);
  d.lightDirRange = vec4(0.0);
  d.lightRadiance = vec4(0.0);
  d.lightCone = vec4(0.0);
  d.viewport = vec4((tile % perRow) * res, (tile / perRow) * res, res, res);
  slots[k].view = d;
  slots[k].pad[0] = vec4(0.0);
  slots[k].pad[1] = vec4(0.0);
}
