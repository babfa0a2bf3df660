#version 460
// GPU skinning: deforms one mesh instance's rest vertices (bind pose, morph targets already
// applied on the CPU) by its joint matrices into its region of the shared vertex buffer that
// the G-buffer (and later shadow and point passes) draw from. Same arithmetic as the CPU
// reference gi::skinVertices: blended matrix sum(w_i J_i) / sum(w_i), identity (bind pose)
// when the weights vanish; normals by the blended matrix's cofactor, rest normal as fallback.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "guards.glsl"

layout(local_size_x = 256) in;

// Vertex = position (3 floats), normal (3), uv (2): 8 floats, tightly packed.
layout(set = 0, binding = 0, std430) readonly buffer Rest { float rest[]; };
layout(set = 0, binding = 1, std430) readonly buffer Skin { uvec4 joints[]; };
layout(set = 0, binding = 2, std430) readonly buffer Weights { vec4 weights[]; };
layout(set = 0, binding = 3, std430) readonly buffer Joints { mat4 jointMatrices[]; };
layout(set = 0, binding = 4, std430) buffer Out { float outVertices[]; };

layout(push_constant) uniform Push {
  uint srcFirst;    // first vertex in Rest / Skin / Weights
  uint dstFirst;    // first vertex in Out
  uint count;       // vertices
  uint jointFirst;  // first matrix of this instance in Joints
  uint jointCount;
} pc;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  uint s = (pc.srcFirst + i) * 8u;
  uint d = (pc.dstFirst + i) * 8u;
  vec3 p = vec3(rest[s], rest[s + 1u], rest[s + 2u]);
  vec3 n = vec3(rest[s + 3u], rest[s + 4u], rest[s + 5u]);

  uvec4 j = joints[pc.srcFirst + i];
  vec4 w = weights[pc.srcFirst + i];
  mat4 m = mat4(0.0);
  float sum = 0.0;
  for (int k = 0; k < 4; ++k) {
    float wk = w[k];
    if (!(wk > 0.0) || isinf(wk) || j[k] >= pc.jointCount) continue;
    m += jointMatrices[pc.jointFirst + j[k]] * wk;
    sum += wk;
  }
  if (giGuard(GI_GUARD_DENOMINATOR, !(sum > 1e-8) || isinf(sum)))  // no usable weight
    m = mat4(1.0);
  else
    m *= 1.0 / sum;

  vec3 sp = (m * vec4(p, 1.0)).xyz;
  bool finite = !giGuard(GI_GUARD_NONFINITE, any(isnan(sp)) || any(isinf(sp)));
  sp = finite ? sp : p;
  vec3 a = m[0].xyz, b = m[1].xyz, c = m[2].xyz;
  mat3 cof = mat3(cross(b, c), cross(c, a), cross(a, b));
  if (dot(a, cross(b, c)) < 0.0) cof = -cof;
  vec3 sn = safeNormalizeCounted(cof * n, n);

  outVertices[d] = sp.x;
  outVertices[d + 1u] = sp.y;
  outVertices[d + 2u] = sp.z;
  outVertices[d + 3u] = sn.x;
  outVertices[d + 4u] = sn.y;
  outVertices[d + 5u] = sn.z;
  outVertices[d + 6u] = rest[s + 6u];
  outVertices[d + 7u] = rest[s + 7u];
}
