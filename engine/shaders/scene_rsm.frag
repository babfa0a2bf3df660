#version 460
// Reflective shadow map texel: the flux the light sends through this texel, reflected with the
// surface's albedo (Dachsbacher and Stamminger 2005). Directional: radiance (irradiance) x the
// texel's world area; point/spot: intensity x the texel's solid angle x cone and range falloff.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"
#include "material.glsl"
#include "scene_view.glsl"

layout(set = 0, binding = 0) uniform View { DrawView drawView; };
layout(set = 0, binding = 3) uniform sampler2D baseColorTexture;

layout(location = 0) in vec3 inWorldPos;
layout(location = 1) in vec3 inWorldNormal;
layout(location = 2) in vec2 inUV;

layout(location = 0) out vec4 outPosition;  // world, w = 1 marks geometry
layout(location = 1) out vec4 outNormal;    // world, facing the light
layout(location = 2) out vec4 outFlux;      // reflected flux (W), rgb

void main() {
  DrawView v = drawView;
  vec3 albedo = material.baseColor.rgb;
  // Untextured materials bind a white texel: exact without a branch on a uniform, which
  // lavapipe (Mesa 22.3) would turn into a leaked shader variant per draw (gbuffer.frag).
  albedo *= texture(baseColorTexture, inUV).rgb;
  albedo = clamp(albedo, 0.0, 1.0);

  int type = int(v.lightPosType.w);
  vec3 towardLight = type == 0 ? -v.lightDirRange.xyz : v.lightPosType.xyz - inWorldPos;
  // Double-sided like the G-buffer: the normal goes to the side of the triangle the light sees.
  vec3 faceN = safeNormalize(cross(dFdx(inWorldPos), dFdy(inWorldPos)), towardLight);
  if (dot(faceN, towardLight) < 0.0) faceN = -faceN;
  vec3 n = safeNormalize(inWorldNormal, faceN);
  if (dot(n, faceN) < 0.0) n = -n;

  vec3 flux;
  if (type == 0) {
    flux = v.lightRadiance.rgb * v.lightCone.z;
  } else {
    // Solid angle of this texel seen from the light.
    vec2 ndc = (gl_FragCoord.xy - v.viewport.xy) / v.viewport.zw * 2.0 - 1.0;
    vec2 texelArea = 2.0 / v.viewport.zw;  // in NDC units per axis
    float solidAngle;
    if (v.params.x > 1.5) {  // paraboloid: d(omega)/dA = 4 / (1 + |p|^2)^2
      float r2 = dot(ndc, ndc);
      solidAngle = texelArea.x * texelArea.y * 4.0 / ((1.0 + r2) * (1.0 + r2));
    } else {
      vec2 t = vec2(1.0 / v.proj[0][0], 1.0 / abs(v.proj[1][1]));
      vec3 d = vec3(ndc * t, 1.0);
      solidAngle = texelArea.x * t.x * texelArea.y * t.y / pow(dot(d, d), 1.5);
    }
    float falloff = 1.0;
    vec3 l = safeNormalize(inWorldPos - v.lightPosType.xyz, v.lightDirRange.xyz);
    if (type == 2) {
      float cd = dot(safeNormalize(v.lightDirRange.xyz, vec3(0, -1, 0)), l);
      falloff *= smoothstep(v.lightCone.y, max(v.lightCone.x, v.lightCone.y + 1e-4), cd);
    }
    float range = v.lightDirRange.w;
    if (range > 0.0) {  // glTF's smooth range window, as lighting applies it
      vec3 toLight = v.lightPosType.xyz - inWorldPos;
      float r = dot(toLight, toLight) / (range * range);
      falloff *= clamp(1.0 - r * r, 0.0, 1.0);
    }
    flux = v.lightRadiance.rgb * solidAngle * falloff;
  }
  outPosition = vec4(inWorldPos, 1.0);
  outNormal = vec4(n, 1.0);
  outFlux = vec4(albedo * flux, 1.0);
}
