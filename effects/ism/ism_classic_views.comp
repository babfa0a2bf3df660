#version 460
// Classic mode: the DrawView record (scene_view.glsl) of each VPL's paraboloid view, from this
// frame's VPL table, for GpuScene::drawDepthFromBuffer -- the same matrix as
// SceneView::paraboloid (glm::lookAt along the VPL normal, up +y or +z when nearly vertical),
// so the classic maps share texels with the ISMs. A VPL without light (position.w 0) gets a
// view that clips every vertex (its tile stays cleared: nothing occludes).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "ism_common.glsl"
#include "scene_view.glsl"

layout(local_size_x = 64) in;
layout(push_constant) uniform Push { int first; int count; } range;  // VPL indices
layout(set = 0, binding = 2, std140) uniform Vpls { Vpl vpls[ISM_VPL_SLOTS]; };
struct Slot {  // gi::kDrawViewStride = 256 bytes
  DrawView view;
  vec4 pad[2];
};
layout(set = 0, binding = 3, std430) writeonly buffer Views { Slot slots[]; };

void main() {
  int k = int(gl_GlobalInvocationID.x);
  if (k >= range.count) return;
  int i = range.first + k;
  Vpl v = vpls[i];
  vec3 eye = v.position.xyz;
  vec3 f = safeNormalize(v.normal.xyz, vec3(0.0, -1.0, 0.0));
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
  d.params = vec4(2.0, ism.bias.z, ism.bias.w, 0.0);  // paraboloid, near, far
  d.lightPosType = vec4(0.0);
  d.lightDirRange = vec4(0.0);
  d.lightRadiance = vec4(0.0);
  d.lightCone = vec4(0.0);
  d.viewport = vec4((i % perRow) * res, (i / perRow) * res, res, res);
  slots[k].view = d;
  slots[k].pad[0] = vec4(0.0);
  slots[k].pad[1] = vec4(0.0);
}
