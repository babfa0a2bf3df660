// Glossy (Phong) receivers for the gathering and the blur (the `glossy` setting). The VPL's
// light reaches x along w = x - x_vpl with irradiance E (vplIrradiance: the singularity clamp
// bounds it); a Phong lobe reflects f0 x (n_p + 2) / (2 pi) cos^n_p(alpha) x E towards the
// camera, alpha between the mirror direction reflect(w, n) and the view direction. The lobe is
// at most (n_p + 2) / (2 pi), so the clamp bounds the glossy term too. CPU mirror:
// gi::ism::phongLobe (ism_params.h). The diffuse and the glossy sums travel as two RGB9E5 words
// (E, and sum E x lobe without f0: the blur multiplies by the pixel's own f0, as the diffuse
// part by its albedo, so textures stay sharp).
#ifndef ISM_GLOSSY_GLSL
#define ISM_GLOSSY_GLSL

const float ISM_MAX_PHONG = 128.0;  // gi::ism::kMaxPhongExponent

// Phong exponent: the setting when > 0, else the one the lighting pass's Blinn-Phong uses for
// this roughness (2 / r^4 - 2), / 4 (a Phong lobe about reflect() is ~twice as wide as a Blinn
// lobe about the half vector), within [1, ISM_MAX_PHONG].
float ismPhongExponent(float setting, float roughness) {
  float r = max(roughness, 0.03);
  float blinn = 2.0 / (r * r * r * r) - 2.0;
  return clamp(setting > 0.0 ? setting : 0.25 * blinn, 1.0, ISM_MAX_PHONG);
}

// Energy-normalised Phong lobe for light travelling along w (VPL -> receiver, any length),
// receiver normal n, unit direction to the camera v. Finite for every input: w = 0 gives 0.
float ismPhongLobe(vec3 w, vec3 n, vec3 v, float exponent) {
  float len = length(w);
  if (!(len > 1e-20)) return 0.0;
  float c = clamp(dot(reflect(w / len, n), v), 0.0, 1.0);
  return (exponent + 2.0) / (2.0 * 3.14159265) * pow(c, exponent);
}

// Shared-exponent RGB (VK_FORMAT_E5B9G9R9_UFLOAT_PACK32's encoding): 9-bit mantissas, values
// in [0, 65408]; negative and NaN inputs become 0.
uint ismPackRgb9e5(vec3 c) {
  c = mix(c, vec3(0.0), isnan(c));
  c = min(max(c, vec3(0.0)), vec3(65408.0));
  float m = max(c.r, max(c.g, c.b));
  int e = int(floor(log2(max(m, exp2(-16.0))))) + 16;  // biased by 15, + 1
  float scale = exp2(float(e - 24));
  if (floor(m / scale + 0.5) >= 512.0) {
    scale *= 2.0;
    ++e;
  }
  uvec3 q = uvec3(min(floor(c / scale + 0.5), vec3(511.0)));
  return q.r | (q.g << 9) | (q.b << 18) | (uint(e) << 27);
}
vec3 ismUnpackRgb9e5(uint v) {
  return vec3(v & 511u, (v >> 9) & 511u, (v >> 18) & 511u) * exp2(float(int(v >> 27) - 24));
}

#endif
