#version 460
// Pull-push (seed 002 §3.2). PUSH = 0: level l+1 from level l, the mean of the valid children
// within the pull threshold of the nearest. PUSH = 1: level l from level l+1, holes and texels
// farther than the push threshold behind the coarse value take it. Thresholds scale by 2^l.
// Tiles are powers of two aligned to their size, so no level mixes two VPLs' maps.
#extension GL_GOOGLE_include_directive : require
#include "ism_common.glsl"

layout(constant_id = 0) const int PUSH = 0;
layout(local_size_x = 32, local_size_y = 16) in;
layout(push_constant) uniform Push { int level, tileBegin, tileEnd; };  // tiles of one bounce
layout(set = 0, binding = 2, r32ui) uniform uimage2D fine;
layout(set = 0, binding = 3, r32ui) uniform uimage2D coarse;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  float scale = float(1 << level);
  // Only the tiles [tileBegin, tileEnd) (one bounce's VPLs): the others are done or empty.
  int tileRes = int(ism.atlas.x) >> (PUSH == 1 ? level : level + 1);  // at p's level
  int tile = p.x / tileRes + int(ism.atlas.y) * (p.y / tileRes);
  if (tile < tileBegin || tile >= tileEnd) return;
  if (PUSH == 0) {
    if (any(greaterThanEqual(p, imageSize(coarse)))) return;
    uint c[4];
    c[0] = imageLoad(fine, 2 * p).x;
    c[1] = imageLoad(fine, 2 * p + ivec2(1, 0)).x;
    c[2] = imageLoad(fine, 2 * p + ivec2(0, 1)).x;
    c[3] = imageLoad(fine, 2 * p + ivec2(1, 1)).x;
    uint nearest = min(min(c[0], c[1]), min(c[2], c[3]));
    uint outv = ISM_EMPTY;
    if (nearest != ISM_EMPTY) {
      float limit = uintBitsToFloat(nearest) + ism.pull.x * scale;
      float sum = 0.0, count = 0.0;
      for (int i = 0; i < 4; ++i) {
        float d = c[i] == ISM_EMPTY ? 3.0e38 : uintBitsToFloat(c[i]);
        bool take = d <= limit;
        sum += take ? d : 0.0;
        count += take ? 1.0 : 0.0;
      }
      outv = floatBitsToUint(sum / max(count, 1.0));
    }
    imageStore(coarse, p, uvec4(outv));
  } else {
    if (any(greaterThanEqual(p, imageSize(fine)))) return;
    uint f = imageLoad(fine, p).x, c = imageLoad(coarse, p / 2).x;
    if (c == ISM_EMPTY) return;
    bool replace = f == ISM_EMPTY || uintBitsToFloat(f) > uintBitsToFloat(c) + ism.pull.y * scale;
    if (replace) imageStore(fine, p, uvec4(c));
  }
}
