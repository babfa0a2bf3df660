#version 460
// The point representation for imperfect shadow maps (seed 002, §3.1): turns each stored
// (instance, triangle, barycentrics) sample into a world-space position and normal from the
// current, possibly GPU-deformed, vertices. Same arithmetic as gi::evaluateSurfacePoints.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = 256) in;

// x: instance, y: the triangle's first index in Indices, z, w: barycentrics b1, b2 (float bits).
layout(set = 0, binding = 0, std430) readonly buffer Samples { uvec4 samples[]; };
layout(set = 0, binding = 1, std430) readonly buffer Instances { Instance instances[]; };
layout(set = 0, binding = 2, std430) readonly buffer Indices { uint indices[]; };
// Vertex = position (3 floats), normal (3), uv (2): 8 floats, tightly packed.
layout(set = 0, binding = 3, std430) readonly buffer Vertices { float vertices[]; };
// Two vec4 per point: world position + represented area, world normal + material index.
layout(set = 0, binding = 4, std430) writeonly buffer Points { vec4 points[]; };

layout(push_constant) uniform Push {
  uint count;
  float areaPerPoint;
} pc;

vec3 position(uint v) { return vec3(vertices[v * 8u], vertices[v * 8u + 1u], vertices[v * 8u + 2u]); }
vec3 normal(uint v) {
  return vec3(vertices[v * 8u + 3u], vertices[v * 8u + 4u], vertices[v * 8u + 5u]);
}

void main() {
  // The grid is 2-D when one row of workgroups would exceed 65535 (dispatch256).
  uint i = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 256u;
  if (i >= pc.count) return;
  uvec4 s = samples[i];
  // Member by member: copying the whole Instance (prevModel included) costs llvmpipe loads.
  uvec4 material = instances[s.x].material;
  uint base = material.y;
  uint i0 = indices[s.y] + base, i1 = indices[s.y + 1u] + base, i2 = indices[s.y + 2u] + base;
  float b1 = uintBitsToFloat(s.z), b2 = uintBitsToFloat(s.w), b0 = 1.0 - b1 - b2;
  vec3 p0 = position(i0), p1 = position(i1), p2 = position(i2);
  vec3 local = b0 * p0 + b1 * p1 + b2 * p2;
  vec3 n = b0 * normal(i0) + b1 * normal(i1) + b2 * normal(i2);
  // Guard: interpolated normals can cancel; fall back to the face normal, then to +y.
  if (!(dot(n, n) > 1e-20)) n = cross(p1 - p0, p2 - p0);
  vec3 wn = safeNormalize(mat3(instances[s.x].normalMatrix) * n, vec3(0.0, 1.0, 0.0));
  points[2u * i] = vec4((instances[s.x].model * vec4(local, 1.0)).xyz, pc.areaPerPoint);
  points[2u * i + 1u] = vec4(wn, float(material.x));
}
