#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "material.glsl"
#include "gbuffer.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
// The draw's base-colour texture (lavapipe has no descriptor indexing: one set per material).
layout(set = 0, binding = 3) uniform sampler2D baseColorTexture;

layout(location = 0) in vec3 inViewNormal;
layout(location = 1) in vec2 inUV;
layout(location = 2) in vec4 inPrevClip;
layout(location = 3) in vec3 inViewPos;

// The packed G-buffer (gbuffer.glsl, gi/gbuffer.h).
layout(location = 0) out uvec4 outGBuffer;  // normal, albedo + roughness, metallic + flags, emission
layout(location = 1) out vec2 outMotion;    // current minus previous position, in UV units

void main() {
  vec4 albedo = material.baseColor;
  // Untextured materials bind a white texel, so this multiply is exact without a branch. No
  // branch on a uniform here: lavapipe (Mesa 22.3) inlines uniforms that feed a branch into a
  // shader variant per draw and never frees them (0.4-0.6 MiB per draw per frame: the animated
  // scene grew 4 MiB a frame; tools/soak, docs/robustness.md).
  albedo *= texture(baseColorTexture, inUV);

  // The triangle's plane normal on the side the camera sees (the fallback when the interpolated
  // normal is degenerate). The interpolated normal is turned to that side, so a double-sided
  // surface shades from either side; it is not turned toward the viewer, which near a
  // silhouette (where interpolated normals face slightly away) would point it into the object.
  vec3 faceN = safeNormalize(cross(dFdx(inViewPos), dFdy(inViewPos)), vec3(0, 0, 1));
  if (dot(faceN, -inViewPos) < 0.0) faceN = -faceN;
  vec3 n = safeNormalize(inViewNormal, faceN);
  if (dot(n, faceN) < 0.0) n = -n;

  // Emission leaves the side the authored normal points to, or both for a double-sided
  // material (the reference's rule). A product, not a branch on the uniform (see above).
  float emitting = max(float(dot(inViewNormal, -inViewPos) >= 0.0), material.params.w);
  outGBuffer = giGBufferEncode(n, albedo.rgb, material.params.x, material.params.y,
                               material.emission.rgb * emitting);
  // This pixel's centre in NDC (what the interpolated clip position divided by w gives).
  vec2 cur = gl_FragCoord.xy * frame.viewport.zw * 2.0 - 1.0;
  vec2 prev = inPrevClip.w > 0.0 ? inPrevClip.xy / inPrevClip.w : cur;
  outMotion = 0.5 * (cur - prev);
}
