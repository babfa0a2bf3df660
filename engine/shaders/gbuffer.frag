#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// The draw's material comes flat from the vertex shader (gbuffer.vert).
// The draw's base-colour texture (lavapipe has no descriptor indexing: one set per material).
layout(set = 0, binding = 3) uniform sampler2D baseColorTexture;

layout(location = 0) in vec3 inViewNormal;
layout(location = 1) in vec2 inUV;
layout(location = 2) in vec4 inClip;
layout(location = 3) in vec4 inPrevClip;
layout(location = 4) in vec3 inViewPos;
layout(location = 5) flat in vec4 inBaseColor;
layout(location = 6) flat in vec4 inEmission;  // rgb, 1
layout(location = 7) flat in vec4 inParams;    // clamped roughness, metallic; textured (1/0)

layout(location = 0) out vec4 outNormal;    // view-space normal, w = 1 marks geometry
layout(location = 1) out vec4 outAlbedo;    // sRGB target: stored encoded, read back linear
layout(location = 2) out vec4 outMaterial;  // roughness, metallic
layout(location = 3) out vec4 outEmission;  // linear radiance
layout(location = 4) out vec2 outMotion;    // current minus previous position, in UV units

void main() {
  vec4 albedo = inBaseColor;
  if (inParams.z > 0.5) albedo *= texture(baseColorTexture, inUV);

  // Geometric fallback when the interpolated normal is degenerate; facing the camera so
  // double-sided surfaces shade from either side.
  vec3 faceN = safeNormalize(cross(dFdx(inViewPos), dFdy(inViewPos)), vec3(0, 0, 1));
  vec3 n = safeNormalize(inViewNormal, faceN);
  if (dot(n, -inViewPos) < 0.0) n = -n;

  outNormal = vec4(n, 1.0);
  outAlbedo = vec4(clamp(albedo.rgb, 0.0, 1.0), 1.0);
  outMaterial = vec4(inParams.xy, 0.0, 1.0);
  outEmission = inEmission;
  vec2 cur = inClip.xy / inClip.w;
  vec2 prev = inPrevClip.w > 0.0 ? inPrevClip.xy / inPrevClip.w : cur;
  outMotion = 0.5 * (cur - prev);
}
