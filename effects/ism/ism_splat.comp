#version 460
// Imperfect shadow maps (seed 002 §3.1): workgroup row y = VPL base + y (a uniform index into the VPL
// table), each invocation one point of the VPL's fixed subset of the point representation
// (points [t P, t P + P) modulo the count, t the VPL's tile: the engine places them in random
// order, so each run is a random subset). The point's distance is splatted with imageAtomicMin
// into the VPL's paraboloid tile as float bits (non-negative floats order like their bits).
// Splat radius in texels from the point's area and distance (the seed: size from squared
// distance), at most MAX_SPLAT (a specialization constant).
// ORTHO: environment VPLs (ism_env_vpl.comp): an orthographic map along -d over the scene's
// bounding sphere (ismOrthoTexel), depth R - (p - c).d, radius from the point's side over the
// texel's, 2R / res.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "ism_common.glsl"

layout(constant_id = 0) const int MAX_SPLAT = 1;
// 1 when the engine's points are fewer than VPLs x points per ISM (capped): the subsets wrap.
// Otherwise no modulo (llvmpipe divides integers lane by lane).
layout(constant_id = 1) const int WRAP = 1;
layout(constant_id = 2) const bool ORTHO = false;
layout(local_size_x = 256) in;
layout(push_constant) uniform Push { int base, firstTile; };  // this bounce's first VPL, tile
layout(set = 0, binding = 2, std140) uniform Vpls { Vpl vpls[ISM_VPL_SLOTS]; };
layout(set = 0, binding = 3, std430) readonly buffer Points { vec4 points[]; };
layout(set = 0, binding = 4, r32ui) uniform coherent uimage2D atlas;

void main() {
  uint v = uint(base) + gl_WorkGroupID.y, tile = uint(firstTile) + gl_WorkGroupID.y;
  uint j = gl_GlobalInvocationID.x;
  uint perIsm = uint(ism.atlas.z), count = uint(ism.atlas.w);
  Vpl vpl = vpls[v];
  if (j >= perIsm || count == 0u || vpl.position.w < 0.5) return;
  uint idx = WRAP == 1 ? (tile * perIsm + j) % count : tile * perIsm + j;
  vec4 pa = points[2u * idx];
  float res = ism.atlas.x;
  // The area the point stands for in this map: the engine's points share the surface, this
  // map holds perIsm of them, so each covers count / perIsm times its own share (a fixed
  // subset that is sparse on a large scene would otherwise leave holes pull-push must fill).
  float area = max(pa.w, 0.0) * max(float(count) / float(perIsm), 1.0);
  ivec2 t;
  uint depth;
  int radius;
  if (ORTHO) {
    vec3 d = vpl.position.xyz, s, u;
    ismBasis(-d, s, u);  // the view's axis, as the classic maps' (ism_classic_views.comp)
    if (!ismOrthoInside(pa.xyz, s, u)) return;  // outside the fitted map: no receiver under it
    t = ismOrthoTexel(tile, pa.xyz, s, u);
    depth = floatBitsToUint(max(ismOrthoDepth(pa.xyz, d), 0.0));
    float side = max(ismOrthoTexelSide(), 1e-30);
    radius = clamp(int(0.5 * sqrt(area) / side * ism.blur.z), 0, MAX_SPLAT);
  } else {
    vec3 w = pa.xyz - vpl.position.xyz;
    float d = length(w);
    vec3 n = vpl.normal.xyz;
    if (!(d > 1e-6)) return;
    vec3 dir = w / d;
    float c = dot(dir, n);
    if (!(c > 0.0)) return;  // behind the VPL's hemisphere
    vec3 s, u;
    ismBasis(n, s, u);
    t = ismTexel(tile, dir, s, u, c);
    depth = floatBitsToUint(d);
    // Point footprint: solid angle area / d^2 against a texel's, 4 (2 / res)^2 / (1 + r^2)^2
    // on the disk (r ~ 1 - c for the radius); radius = half the footprint's width.
    vec2 pd = vec2(dot(dir, s), dot(dir, u)) / (1.0 + c);
    float r2 = dot(pd, pd);
    float texelOmega = 16.0 / (res * res) / ((1.0 + r2) * (1.0 + r2));
    float omega = area / (d * d);
    radius = clamp(int(0.5 * sqrt(omega / texelOmega) * ism.blur.z), 0, MAX_SPLAT);
  }
  if (MAX_SPLAT == 0) {
    imageAtomicMin(atlas, t, depth);
  } else {
    ivec2 lo = ismTileOrigin(tile);
    ivec2 hi = lo + ivec2(int(res) - 1);
    // Loops bounded by the lanes' own radius: llvmpipe runs a loop only while some lane is
    // active, so 8 points of radius 0 cost one atomic each, not (2 MAX_SPLAT + 1)^2 masked ones.
    for (int y = -radius; y <= radius; ++y)
      for (int x = -radius; x <= radius; ++x)
        imageAtomicMin(atlas, clamp(t + ivec2(x, y), lo, hi), depth);
  }
}
