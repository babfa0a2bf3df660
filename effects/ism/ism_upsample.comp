#version 460
// Geometry-aware upsampling of the irradiance gathered and blurred at 1 / SCALE resolution
// (gather_scale > 1): low-resolution pixel q stands for G-buffer pixel q x SCALE. Each pixel
// takes the bilinear mix of its 4 nearest low-resolution samples, keeping only those near its
// tangent plane with a similar normal (the blur's test); when none passes, the plain bilinear
// mix (a thin feature no sample landed on). Then reflects like the blur's y pass:
// indirect = diffuse albedo / pi x irradiance (+ f0 x the Phong-weighted sum with GLOSSY, whose
// texels carry both as RGB9E5 words: ism_glossy.glsl).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "ism_common.glsl"
#include "ism_glossy.glsl"

layout(constant_id = 0) const int SCALE = 2;
layout(constant_id = 1) const bool GLOSSY = false;
layout(local_size_x = 32, local_size_y = 16) in;
layout(set = 0, binding = 0) uniform Frame { FrameUniforms frame; };
layout(set = 0, binding = 2) uniform usampler2D lowRaw;
layout(set = 0, binding = 3) uniform sampler2D gDepth;
#define GI_GBUFFER_BINDING 4
#include "gbuffer.glsl"  // the packed G-buffer (normal, albedo, metallic)
layout(set = 0, binding = 7, rgba16f) uniform writeonly image2D outIndirect;
// An earlier effect's "indirect" (1x1 0 when none), added: ISM is its far field.
layout(set = 0, binding = 8) uniform sampler2D priorIndirect;


void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = ivec2(frame.viewport.xy);
  if (p.x >= size.x || p.y >= size.y) return;
  float depth = texelFetch(gDepth, p, 0).r;
  vec3 viewPos = viewPositionFromDepth(frame.invProj, (vec2(p) + 0.5) * frame.viewport.zw, depth);
  uvec4 surface = giGBufferLoad(p);
  vec3 n = giGBufferNormal(surface);
  float z = length(viewPos);
  ivec2 lowSize = textureSize(lowRaw, 0);
  vec2 u = vec2(p) / float(SCALE);
  ivec2 b = ivec2(floor(u));
  vec2 f = u - vec2(b);
  vec3 sum = vec3(0.0), any = vec3(0.0), specSum = vec3(0.0), specAny = vec3(0.0);
  float wsum = 0.0, asum = 0.0;
  for (int i = 0; i < 4; ++i) {
    ivec2 o = ivec2(i & 1, i >> 1);
    ivec2 q = min(b + o, lowSize - 1);
    uvec4 t = texelFetch(lowRaw, q, 0);
    float zt = uintBitsToFloat(t.z);
    float bil = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
    vec2 uvq = (vec2(min(q * SCALE, size - 1)) + 0.5) * frame.viewport.zw;
    vec3 pt = normalize(viewPositionFromDepth(frame.invProj, uvq, 0.5)) * zt;
    bool same = zt > 0.0 && abs(dot(n, pt - viewPos)) <= ism.blur.x * z &&
                dot(giDecodeNormal(t.w), n) >= ism.blur.y;
    vec3 e = GLOSSY ? ismUnpackRgb9e5(t.x) : vec3(unpackHalf2x16(t.x), unpackHalf2x16(t.y).x);
    vec3 s = GLOSSY ? ismUnpackRgb9e5(t.y) : vec3(0.0);
    float w = same ? bil + 1e-6 : 0.0;  // + 1e-6: a passing sample at bilinear weight 0 counts
    sum += w * e;
    specSum += w * s;
    wsum += w;
    float wa = zt > 0.0 ? bil : 0.0;
    any += wa * e;
    specAny += wa * s;
    asum += wa;
  }
  vec3 e = wsum > 0.0 ? sum / wsum : any / max(asum, 1e-6);
  vec3 spec = wsum > 0.0 ? specSum / wsum : specAny / max(asum, 1e-6);
  vec3 albedo = giGBufferAlbedo(surface);
  float metallic = giGBufferMetallic(surface);
  vec3 l = albedo * (1.0 - metallic) * e / 3.14159265;
  if (GLOSSY) l += mix(vec3(0.04), albedo, metallic) * spec;
  l += max(textureLod(priorIndirect, (vec2(p) + 0.5) * frame.viewport.zw, 0.0).rgb, vec3(0.0));
  vec3 outv = isSky(depth) ? vec3(0.0) : min(l, vec3(65000.0));
  imageStore(outIndirect, p, vec4(outv, 1.0));
}
