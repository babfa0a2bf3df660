// Guard counting (gi/vk/guard_counters.h): a guard that changes a value calls
// giGuardFired(kind). Pipelines made while counting is on (the hard-case sweep) add one to
// their counter of that kind; otherwise the specialization constant compiles it out, and the
// engine binds the counters itself. Compute shaders only (fragment stores need a feature).
#ifndef GI_GUARDS_GLSL
#define GI_GUARDS_GLSL

layout(constant_id = 1000) const bool giCountGuards = false;
layout(set = 0, binding = 63, std430) buffer GiGuardCounters { uint giGuardFiredCount[]; };

const int GI_GUARD_NONFINITE = 0;    // a NaN or infinity replaced
const int GI_GUARD_RANGE = 1;        // a value clamped to its range (half-float radiance, [0, 1])
const int GI_GUARD_DISTANCE = 2;     // a distance clamp: 1 / max(d^2, d_min^2)
const int GI_GUARD_ZERO_VECTOR = 3;  // normalize of a (near) zero vector took its fallback
const int GI_GUARD_DENOMINATOR = 4;  // an epsilon kept a denominator from 0

void giGuardFired(int kind) {
  if (giCountGuards) atomicAdd(giGuardFiredCount[kind], 1u);
}

// Returns `fires` and counts it: `if (giGuard(GI_GUARD_..., x > limit)) x = limit;`.
bool giGuard(int kind, bool fires) {
  if (fires) giGuardFired(kind);
  return fires;
}

// common.glsl's guards, counted (include common.glsl first).
vec3 giClampRadianceCounted(vec3 c) {
  giGuard(GI_GUARD_NONFINITE, any(isnan(c)));
  giGuard(GI_GUARD_RANGE, any(greaterThan(abs(c), vec3(GI_MAX_RADIANCE))));
  return giClampRadiance(c);
}
vec3 safeNormalizeCounted(vec3 v, vec3 fallback) {
  float len2 = dot(v, v);
  giGuard(GI_GUARD_ZERO_VECTOR, !(len2 > 1e-30 && !isinf(len2) && !isnan(len2)));
  return safeNormalize(v, fallback);
}

#endif
