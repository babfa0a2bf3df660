#version 460
// Pull-push (seed 002 §3.2) in one pass, tile-local. LEVELS levels only mix the texels of one
// aligned 2^LEVELS block (2^LEVELS <= the tile side: never two VPLs' maps), so a workgroup
// takes a 64 x 64 block of the atlas (LEVELS <= 6) and runs every level on it: each invocation
// pulls its 4 x 4 texels through levels 1 and 2 in registers, levels 3..6 go through shared
// memory, then the push comes back down the same way and each texel is stored once. Replaces
// one dispatch per level over the whole atlas (and the coarse mips). Pull: level l+1 = the
// mean of the valid children within the pull threshold of the nearest. Push: a level-l texel
// that is a hole, or lies more than the push threshold behind a coarse value that stands for
// most of its children, takes it.
// Thresholds scale by 2^l (l: the finer level); the rules are gi::ism::pullDepth/pushDepth.
#extension GL_GOOGLE_include_directive : require
#include "ism_common.glsl"

layout(constant_id = 0) const int LEVELS = 1;  // 1..6
layout(local_size_x = 16, local_size_y = 16) in;
// Tiles [tileBegin, tileEnd) (one bounce's, or the environment VPLs'); the dispatch covers only
// the 64-texel block rows from firstBlockRow that hold them (an idle workgroup still costs).
layout(push_constant) uniform Push { int tileBegin, tileEnd, firstBlockRow; };
layout(set = 0, binding = 2, r32ui) uniform uimage2D atlas;

// Levels 2..6 of the 64 x 64 block: 16^2 + 8^2 + 4^2 + 2^2 + 1 texels.
const int OFFSET[7] = int[7](0, 0, 0, 256, 320, 336, 340);
shared uint level[341];

// The lowest bit of a pulled value (a 1-ulp change of its distance) says whether the near
// children were at least half of the valid ones: only such a coarse value replaces a texel
// behind it (gi::ism::pushDepth); behind a minority the texel is beside a silhouette and stays.
uint depthBits(uint v) { return v == ISM_EMPTY ? v : v & ~1u; }  // without the flag

uint pull(uint a, uint b, uint c, uint d, float threshold) {
  a = depthBits(a);
  b = depthBits(b);
  c = depthBits(c);
  d = depthBits(d);
  uint nearest = min(min(a, b), min(c, d));  // distances order like their float bits
  if (nearest == ISM_EMPTY) return ISM_EMPTY;
  float limit = uintBitsToFloat(nearest) + threshold;
  float sum = 0.0, count = 0.0, valid = 0.0;
  uint v[4] = uint[4](a, b, c, d);
  for (int i = 0; i < 4; ++i) {
    bool take = v[i] != ISM_EMPTY && uintBitsToFloat(v[i]) <= limit;
    sum += take ? uintBitsToFloat(v[i]) : 0.0;
    count += take ? 1.0 : 0.0;
    valid += v[i] != ISM_EMPTY ? 1.0 : 0.0;
  }
  uint mean = floatBitsToUint(sum / max(count, 1.0)) & ~1u;
  return mean | (2.0 * count >= valid ? 1u : 0u);
}

uint push(uint fine, uint coarse, float threshold) {
  if (coarse == ISM_EMPTY) return fine;
  bool behind = uintBitsToFloat(depthBits(fine)) > uintBitsToFloat(depthBits(coarse)) + threshold;
  bool replace = fine == ISM_EMPTY || ((coarse & 1u) != 0u && behind);
  return replace ? coarse : fine;
}

float threshold(float t, int l) { return t * float(1 << l); }

void main() {
  ivec2 size = imageSize(atlas);
  int shift = findLSB(int(ism.atlas.x));
  ivec2 lid = ivec2(gl_LocalInvocationID.xy);
  ivec2 origin = (ivec2(gl_WorkGroupID.xy) + ivec2(0, firstBlockRow)) * 64 + lid * 4;
  uint t0[16];
  for (int i = 0; i < 16; ++i) {
    ivec2 q = origin + ivec2(i % 4, i / 4);
    t0[i] = all(lessThan(q, size)) ? imageLoad(atlas, q).x : ISM_EMPTY;
  }
  // Level 1 (2 x 2) and level 2 (1) in registers.
  uint t1[4];
  for (int i = 0; i < 4; ++i) {
    int x = 2 * (i % 2), y = 2 * (i / 2);
    t1[i] = pull(t0[y * 4 + x], t0[y * 4 + x + 1], t0[y * 4 + x + 4], t0[y * 4 + x + 5],
                 threshold(ism.pull.x, 0));
  }
  if (LEVELS >= 2) {
    uint t2 = pull(t1[0], t1[1], t1[2], t1[3], threshold(ism.pull.x, 1));
    if (LEVELS >= 3) {
      int self = lid.y * 16 + lid.x;
      level[self] = t2;
      barrier();
      for (int l = 3; l <= LEVELS; ++l) {  // level l from level l - 1 (dims 64 >> l)
        int dims = 64 >> l, i = self;
        if (i < dims * dims) {
          ivec2 c = 2 * ivec2(i % dims, i / dims);
          int fine = OFFSET[l - 1], fd = 2 * dims;
          level[OFFSET[l] + i] = pull(level[fine + c.y * fd + c.x], level[fine + c.y * fd + c.x + 1],
                                      level[fine + (c.y + 1) * fd + c.x],
                                      level[fine + (c.y + 1) * fd + c.x + 1],
                                      threshold(ism.pull.x, l - 1));
        }
        barrier();
      }
      for (int l = LEVELS - 1; l >= 2; --l) {  // level l from level l + 1
        int dims = 64 >> l, i = self;
        if (i < dims * dims) {
          ivec2 c = ivec2(i % dims, i / dims) / 2;
          level[OFFSET[l] + i] = push(level[OFFSET[l] + i], level[OFFSET[l + 1] + c.y * (dims / 2) + c.x],
                                      threshold(ism.pull.y, l));
        }
        barrier();
      }
      t2 = level[self];
    }
    for (int i = 0; i < 4; ++i) t1[i] = push(t1[i], t2, threshold(ism.pull.y, 1));
  }
  for (int i = 0; i < 16; ++i) {
    ivec2 q = origin + ivec2(i % 4, i / 4);
    uint v = push(t0[i], t1[(i / 8) * 2 + (i % 4) / 2], threshold(ism.pull.y, 0));
    ivec2 tileQ = q >> shift;  // tiles are powers of two (llvmpipe divides lane by lane)
    int tile = tileQ.x + int(ism.atlas.y) * tileQ.y;
    if (all(lessThan(q, size)) && tile >= tileBegin && tile < tileEnd && v != t0[i])
      imageStore(atlas, q, uvec4(v));
  }
}
