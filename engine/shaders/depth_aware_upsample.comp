#version 460
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// The depth-aware upsample of the engine's reduced-resolution blur (gi/depth_aware_blur.h):
// low-resolution pixel q (a depthAwareBlurPack texel, slopes per low-resolution pixel) stands
// for frame pixel q x kScale. Each frame pixel mixes its 4 nearest low-resolution values
// bilinearly, keeping those whose tangent plane, extended to it, predicts its own 1/z within
// the tolerance (the blur's test: no value crosses a depth edge or leaves its plane). When none
// passes (a feature thinner than kScale pixels, which no low-resolution pixel landed on), the
// value whose plane comes nearest. Sky pixels mix the sky samples' values (the effect's value
// for no geometry), or all four when none is sky.
layout(local_size_x = 32, local_size_y = 16) in;

layout(constant_id = 0) const int kScale = 2;  // 2..gi::DepthAwareBlur::kMaxScale
layout(set = 0, binding = 0) uniform sampler2D inPacked;
layout(set = 0, binding = 1, r16f) uniform writeonly image2D outValue;
layout(set = 0, binding = 2) uniform sampler2D gDepth;
layout(set = 0, binding = 3) uniform Frame { FrameUniforms frame; };
layout(push_constant) uniform Push { float tolerance; } push;  // world units

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = imageSize(outValue);
  if (p.x >= size.x || p.y >= size.y) return;

  float depth = texelFetch(gDepth, p, 0).r;
  vec3 P = viewPositionFromDepth(frame.invProj, (vec2(p) + 0.5) * frame.viewport.zw, depth);
  // Guard: sky, the far plane of an infinite projection and a point behind the eye have no
  // 1/z (0: only the bilinear mix below).
  float dist = -P.z;
  float ip = !isSky(depth) && dist > 0.0 && !isinf(dist) ? 1.0 / dist : 0.0;

  ivec2 lowSize = textureSize(inPacked, 0);
  vec2 u = vec2(p) / float(kScale);  // in low-resolution pixels
  ivec2 b = ivec2(floor(u));
  vec2 f = u - vec2(b);
  float sum = 0.0, weights = 0.0, mixAll = 0.0, sky = 0.0, skyWeights = 0.0, nearest = 0.0,
        nearestGap = 1e38;
  for (int i = 0; i < 4; ++i) {
    ivec2 o = ivec2(i & 1, i >> 1);
    ivec2 q = min(b + o, lowSize - 1);
    vec4 t = texelFetch(inPacked, q, 0);
    float bil = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
    mixAll += bil * t.x;
    // Sky takes sky (its own value, as the blur keeps it): + 1e-6 as below.
    float ws = t.y > 0.0 ? 0.0 : bil + 1e-6;
    sky += ws * t.x;
    skyWeights += ws;
    float pred = t.y + dot(t.zw, u - vec2(q));
    // |1/ip - 1/pred| in world units, without a division (ip, pred > 0); sky samples (t.y = 0)
    // and planes that do not reach this pixel (pred <= 0) never count.
    bool valid = ip > 0.0 && t.y > 0.0 && pred > 0.0;
    float gap = abs(pred - ip);
    bool same = valid && gap < push.tolerance * ip * pred;
    // + 1e-6: a passing sample at bilinear weight 0 still counts (the corners of q's footprint).
    float w = same ? bil + 1e-6 : 0.0;
    sum += w * t.x;
    weights += w;
    float relGap = valid ? gap / (ip * pred) : 1e38;
    nearest = relGap < nearestGap ? t.x : nearest;
    nearestGap = min(nearestGap, relGap);
  }
  float value = ip > 0.0 ? (weights > 0.0 ? sum / weights : (nearestGap < 1e38 ? nearest : mixAll))
                         : (skyWeights > 0.0 ? sky / skyWeights : mixAll);
  imageStore(outValue, p, vec4(value));
}
