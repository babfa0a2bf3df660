#include "gi/reference/reference.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <thread>
#include <vector>

#include "gi/environment.h"
#include "gi/errors.h"
#include "gi/reference/ray_scene.h"

namespace gi::reference {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
// The rasteriser's guard: squared light distance is clamped so a light on a surface stays finite.
constexpr float kMinLightDistance2 = 1e-4f;

[[noreturn]] void usage(const std::string& message) {
  throw Error(ErrorKind::Usage, "", message);
}

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

glm::vec3 safeNormalize(const glm::vec3& v, const glm::vec3& fallback) {
  const float len2 = glm::dot(v, v);
  return (len2 > 1e-30f && std::isfinite(len2)) ? v / std::sqrt(len2) : fallback;
}

glm::vec3 finiteOrZero(const glm::vec3& v) {
  return finite(v) ? v : glm::vec3(0.0f);
}

float smoothstep(float e0, float e1, float x) {
  const float t = std::clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

// Base-colour texture decoded to linear once; sampled bilinearly with repeat wrapping (the
// rasteriser's sampler for base colour).
struct LinearTexture {
  int width = 1, height = 1;
  std::vector<glm::vec3> texels{glm::vec3(1.0f)};

  explicit LinearTexture(const Texture& t) {
    if (t.width <= 0 || t.height <= 0 || t.rgba8.size() != size_t(t.width) * t.height * 4)
      return;  // invalid: white, like the rasteriser
    float table[256];
    for (int i = 0; i < 256; ++i) {
      const float c = float(i) / 255.0f;
      table[i] = c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
    }
    width = t.width;
    height = t.height;
    texels.resize(size_t(width) * height);
    for (size_t i = 0; i < texels.size(); ++i)
      texels[i] =
          glm::vec3(table[t.rgba8[i * 4]], table[t.rgba8[i * 4 + 1]], table[t.rgba8[i * 4 + 2]]);
  }

  glm::vec3 sample(glm::vec2 uv) const {
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) uv = glm::vec2(0.0f);
    const float fx = uv.x * float(width) - 0.5f, fy = uv.y * float(height) - 0.5f;
    const float x0f = std::floor(fx), y0f = std::floor(fy);
    const float ax = fx - x0f, ay = fy - y0f;
    auto wrap = [](double i, int n) {
      const double m = std::fmod(i, double(n));
      return int(m < 0 ? m + n : m) % n;
    };
    const int x0 = wrap(x0f, width), x1 = wrap(double(x0f) + 1, width);
    const int y0 = wrap(y0f, height), y1 = wrap(double(y0f) + 1, height);
    auto at = [&](int x, int y) { return texels[size_t(y) * width + x]; };
    return glm::mix(glm::mix(at(x0, y0), at(x1, y0), ax), glm::mix(at(x0, y1), at(x1, y1), ax), ay);
  }
};

struct WorldLight {
  LightType type = LightType::Point;
  glm::vec3 position{0.0f};
  glm::vec3 direction{0.0f, -1.0f, 0.0f};  // where the light points (unit)
  glm::vec3 radiance{0.0f};                // colour * intensity (lux or candela)
  float range = 0.0f, cosInner = 1.0f, cosOuter = 0.0f;
  bool shadows = true;
};

// An emissive triangle, sampled for next-event estimation in the bounce. It lights the side
// its interpolated vertex normals point to (both for a double-sided material).
struct Emitter {
  glm::vec3 p0{0.0f}, e1{0.0f}, e2{0.0f}, normal{0.0f, 1.0f, 0.0f}, emission{0.0f};
  glm::vec3 n0{0.0f}, n1{0.0f}, n2{0.0f};
  bool doubleSided = false;
};

float luminance(const glm::vec3& c) {
  return (c.x + c.y + c.z) / 3.0f;
}

// The lighting pass's BRDF (lighting.comp, lights.glsl): Lambert with the diffuse colour for
// every light, plus a normalised Blinn-Phong lobe for the point, spot and directional lights
// only (the renderer has no specular term for the environment or indirect light).
struct SurfaceMaterial {
  glm::vec3 diffuse{0.0f};   // albedo * (1 - metallic): the Lambert colour (BRDF = diffuse / pi)
  glm::vec3 emission{0.0f};  // 0 where a one-sided emitter is seen from behind
  glm::vec3 f0{0.04f};       // specular colour: mix(0.04, albedo, metallic)
  float shininess = 1.0f;    // Blinn-Phong exponent of the roughness (shininessOf)
};

// lights.glsl's shininessOf: the Blinn-Phong exponent of a roughness.
float shininessOf(float roughness) {
  const float r = std::max(roughness, 0.03f);
  return std::clamp(2.0f / (r * r * r * r) - 2.0f, 1.0f, 4096.0f);
}

// Everything a sample needs, shared read-only by the worker threads.
class Shading {
 public:
  Shading(const Scene& scene, const RayScene& rays) : rays_(rays), env_(scene.environment) {
    if (env_.kind == Environment::Kind::Map) envSampler_.emplace(env_);
    materials_ = scene.materials;
    if (materials_.empty()) materials_.emplace_back();
    for (const Texture& t : scene.textures) textures_.emplace_back(t);
    for (const Node& node : scene.nodes) {
      if (node.light < 0 || size_t(node.light) >= scene.lights.size()) continue;
      const Light& l = scene.lights[node.light];
      WorldLight w;
      w.type = l.type;
      w.position = glm::vec3(node.world * glm::vec4(0, 0, 0, 1));
      w.direction =
          safeNormalize(glm::vec3(node.world * glm::vec4(0, 0, -1, 0)), glm::vec3(0, -1, 0));
      w.radiance = l.color * std::max(l.intensity, 0.0f);
      w.range = std::max(l.range, 0.0f);
      w.cosInner = std::cos(l.innerConeAngle);
      w.cosOuter = std::cos(l.outerConeAngle);
      w.shadows = l.castsShadows;
      if (!finite(w.position) || !finite(w.radiance)) continue;
      lights_.push_back(w);
    }
    // Emissive triangles, chosen with probability proportional to area * luminance(Le).
    auto emission = [&](uint32_t m) {
      const glm::vec3 e = materials_[std::min<size_t>(m, materials_.size() - 1)].emission;
      return finite(e) ? glm::max(e, glm::vec3(0.0f)) : glm::vec3(0.0f);
    };
    for (const WorldTriangle& t :
         rays.triangles([&](uint32_t m) { return luminance(emission(m)) > 0.0f; })) {
      Emitter e;
      e.p0 = t.p0;
      e.e1 = t.p1 - t.p0;
      e.e2 = t.p2 - t.p0;
      const glm::vec3 c = glm::cross(e.e1, e.e2);
      const float area = 0.5f * glm::length(c);
      if (!(area > 0.0f) || !std::isfinite(area)) continue;
      e.normal = c / (2.0f * area);
      e.emission = emission(t.material);
      e.n0 = t.n0;
      e.n1 = t.n1;
      e.n2 = t.n2;
      e.doubleSided = materials_[std::min<size_t>(t.material, materials_.size() - 1)].doubleSided;
      emitterPower_ += double(area) * luminance(e.emission);
      emitterCdf_.push_back(emitterPower_);
      emitters_.push_back(e);
    }
  }

  const RayScene& rays() const { return rays_; }

  SurfaceMaterial material(const SurfaceHit& hit) const {
    const Material& m = materials_[std::min<size_t>(hit.material, materials_.size() - 1)];
    glm::vec3 albedo(m.baseColor);
    if (m.baseColorTexture >= 0 && size_t(m.baseColorTexture) < textures_.size())
      albedo *= textures_[m.baseColorTexture].sample(hit.uv);
    albedo = glm::clamp(finiteOrZero(albedo), 0.0f, 1.0f);
    const float metallic = std::isfinite(m.metallic) ? std::clamp(m.metallic, 0.0f, 1.0f) : 0.0f;
    const float roughness = std::isfinite(m.roughness) ? std::clamp(m.roughness, 0.0f, 1.0f) : 0.0f;
    const bool emits = hit.frontFacing || m.doubleSided;
    return {albedo * (1.0f - metallic),
            emits ? glm::max(finiteOrZero(m.emission), glm::vec3(0.0f)) : glm::vec3(0.0f),
            glm::mix(glm::vec3(0.04f), albedo, metallic), shininessOf(roughness)};
  }

  glm::vec3 environment(const glm::vec3& dir) const { return environmentRadiance(env_, dir); }

  // The environment light a diffuse point reflects, per unit diffuse albedo. A map is sampled
  // twice and the two combined by multiple importance sampling (balance heuristic): along the
  // cosine-sampled direction `dir` the caller traces anyway (`escaped`: it reached the sky),
  // weighted p_cos / (p_cos + p_env), and along one direction drawn from the map's importance
  // (EnvironmentSampler, its own shadow ray), L cos / pi / (p_cos + p_env): a small bright
  // source (a sun in an HDR map) that cosine samples alone would rarely find. Sky and constant
  // environments keep the cosine sample alone (their references unchanged).
  glm::vec3 environmentLight(const SurfaceHit& x, const glm::vec3& dir, bool escaped,
                             Rng& rng) const {
    const glm::vec3 n = x.shadingNormal;
    if (!envSampler_) return escaped ? environment(dir) : glm::vec3(0.0f);
    const float cosPdf = std::max(glm::dot(n, dir), 0.0f) * float(1.0 / M_PI);
    glm::vec3 sum(0.0f);
    if (escaped) {
      const float envPdf = envSampler_->pdf(dir);
      // Guard: a zero denominator (a grazing direction of a black texel) adds nothing.
      if (cosPdf + envPdf > 0.0f) sum += environment(dir) * (cosPdf / (cosPdf + envPdf));
    }
    const float u1 = rng.uniform(), u2 = rng.uniform();
    const EnvironmentSampler::Sample e = envSampler_->sample(u1, u2);
    const float cosE = glm::dot(n, e.direction);
    if (cosE > 0.0f && e.pdf > 0.0f &&
        !rays_.occluded(RayScene::spawnOrigin(x), e.direction, 0.0f, kInf)) {
      const float cosPdfE = cosE * float(1.0 / M_PI);
      sum += environment(e.direction) * (cosPdfE / (cosPdfE + e.pdf));
    }
    return finiteOrZero(sum);
  }

  // Radiance the point reflects towards `v` (unit) from the point, spot and directional lights
  // with shadow rays: sum (diffuse / pi + f0 (s + 8) / (8 pi) max(n.h, 0)^s) E_l cos(theta_l)
  // V_l, with the rasteriser's units, falloffs and lobe (lights.glsl sumLights).
  glm::vec3 directLights(const SurfaceHit& hit, const SurfaceMaterial& m,
                         const glm::vec3& v) const {
    glm::vec3 sum(0.0f);
    if (lights_.empty()) return sum;
    const glm::vec3 n = hit.shadingNormal;
    const glm::vec3 origin = RayScene::spawnOrigin(hit);
    for (const WorldLight& light : lights_) {
      glm::vec3 l;
      float attenuation = 1.0f;
      if (light.type == LightType::Directional) {
        l = -light.direction;
      } else {
        const glm::vec3 toLight = light.position - hit.position;
        const float d2 = std::max(glm::dot(toLight, toLight), kMinLightDistance2);
        l = toLight / std::sqrt(d2);
        attenuation = 1.0f / d2;
        if (light.range > 0.0f) {  // glTF's recommended smooth range window
          const float r = d2 / (light.range * light.range);
          attenuation *= std::clamp(1.0f - r * r, 0.0f, 1.0f);
        }
        if (light.type == LightType::Spot) {
          const float cd = glm::dot(light.direction, -l);
          attenuation *=
              smoothstep(light.cosOuter, std::max(light.cosInner, light.cosOuter + 1e-4f), cd);
        }
      }
      const float ndl = std::max(glm::dot(n, l), 0.0f);
      if (!(ndl > 0.0f) || !(attenuation > 0.0f)) continue;
      if (light.shadows) {
        const bool blocked = light.type == LightType::Directional
                                 ? rays_.occluded(origin, l, 0.0f, kInf)
                                 : rays_.occluded(origin, light.position - origin, 0.0f, 0.9999f);
        if (blocked) continue;
      }
      const glm::vec3 h = safeNormalize(l + v, n);
      const float lobe = (m.shininess + 8.0f) / (8.0f * kPi) *
                         std::pow(std::max(glm::dot(n, h), 0.0f), m.shininess);
      sum += (m.diffuse / kPi + m.f0 * lobe) * light.radiance * (attenuation * ndl);
    }
    return finiteOrZero(sum);
  }

  // Light-sampling density (per unit area) of a point on an emitter of radiance `le`.
  double emitterAreaPdf(const glm::vec3& le) const {
    return emitterPower_ > 0.0 ? luminance(le) / emitterPower_ : 0.0;
  }

  // MIS weight (balance heuristic) of the cosine-sampled direction `dir` from `x` that hit the
  // emitter point `y`, against light sampling of the emitters.
  float bsdfWeight(const SurfaceHit& x, const glm::vec3& dir, const SurfaceHit& y,
                   const glm::vec3& le) const {
    const double pArea = emitterAreaPdf(le);
    if (pArea <= 0.0) return 1.0f;
    const double cosY = std::abs(glm::dot(y.geometricNormal, dir));
    const double pBsdf = std::max(0.0f, glm::dot(x.shadingNormal, dir)) / kPi;
    if (cosY <= 0.0) return 1.0f;
    const double pLight = pArea * double(y.t) * y.t / cosY;
    return float(pBsdf / (pBsdf + pLight));
  }

  // Next-event estimation of the light the emissive surfaces send to `x` directly (from their
  // front side, or both for double-sided ones; shadow ray), MIS-weighted against the
  // cosine-sampled bounce: returns
  // Le cos_x / pi / (p_light + p_bsdf), to be multiplied by the diffuse colour.
  glm::vec3 sampleEmitters(const SurfaceHit& x, Rng& rng) const {
    if (emitters_.empty()) return glm::vec3(0.0f);
    const double u = double(rng.uniform()) * emitterPower_;
    const size_t k = std::min<size_t>(
        size_t(std::upper_bound(emitterCdf_.begin(), emitterCdf_.end(), u) - emitterCdf_.begin()),
        emitters_.size() - 1);
    const Emitter& e = emitters_[k];
    const float su = std::sqrt(rng.uniform()), v = rng.uniform();
    const float b1 = su * (1.0f - v), b2 = su * v;
    const glm::vec3 point = e.p0 + b1 * e.e1 + b2 * e.e2;
    const glm::vec3 w = point - x.position;
    const float d2 = glm::dot(w, w);
    if (!(d2 > 0.0f) || !std::isfinite(d2)) return glm::vec3(0.0f);
    const glm::vec3 wn = w / std::sqrt(d2);
    // The same side test as a ray that hits the emitter (SurfaceHit::frontFacing).
    const glm::vec3 front = (1.0f - b1 - b2) * e.n0 + b1 * e.n1 + b2 * e.n2;
    if (!e.doubleSided && glm::dot(safeNormalize(front, e.normal), -wn) < 0.0f)
      return glm::vec3(0.0f);
    const float cosX = glm::dot(x.shadingNormal, wn);
    const float cosY = std::abs(glm::dot(e.normal, wn));
    if (!(cosX > 0.0f) || !(cosY > 0.0f)) return glm::vec3(0.0f);
    const glm::vec3 origin = RayScene::spawnOrigin(x);
    if (rays_.occluded(origin, point - origin, 0.0f, 0.9999f)) return glm::vec3(0.0f);
    const double pLight = emitterAreaPdf(e.emission) * d2 / cosY;
    const double pBsdf = cosX / kPi;
    return e.emission * float((cosX / kPi) / (pLight + pBsdf));
  }

 private:
  const RayScene& rays_;
  Environment env_;
  std::optional<EnvironmentSampler> envSampler_;  // a map's importance sampling (MIS)
  std::vector<Material> materials_;
  std::vector<LinearTexture> textures_;
  std::vector<WorldLight> lights_;
  std::vector<Emitter> emitters_;
  std::vector<double> emitterCdf_;  // running sum of area * luminance
  double emitterPower_ = 0.0;
};

// What a pixel's samples start from: its primary hit and the deterministic light terms.
struct Primary {
  bool geometry = false;
  SurfaceHit hit;
  SurfaceMaterial material;
  glm::vec3 base{0.0f};  // Le + direct light from the point/spot/directional lights
};

glm::vec3 cosineDirection(const glm::vec3& n, Rng& rng) {
  const float u1 = rng.uniform(), u2 = rng.uniform();
  return Basis(n).toWorld(cosineHemisphere(u1, u2));
}

// The light diffuse surface y (material my) reflects towards the previous path vertex, one
// sample: its direct light (lights with shadow rays) plus, along one cosine-sampled direction,
// the environment or, with `more` bounces left, what the surface z met there sends (its
// emission, unweighted: no vertex after the first samples the emitters directly, so this is
// their only estimator there, plus the same reflection one level down). With more = 0 this is
// the one-bounce estimator's vertex exactly (same random numbers, an occlusion ray).
glm::vec3 reflected(const Shading& shading, const SurfaceHit& y, const SurfaceMaterial& my,
                    const glm::vec3& toPrevious, uint32_t more, bool emitterLight, Rng& rng) {
  const RayScene& rays = shading.rays();
  glm::vec3 l = shading.directLights(y, my, toPrevious);
  const glm::vec3 dir = cosineDirection(y.shadingNormal, rng);
  const glm::vec3 origin = RayScene::spawnOrigin(y);
  if (more == 0) {
    const bool escaped = !rays.occluded(origin, dir, 0.0f, kInf);
    return l + my.diffuse * shading.environmentLight(y, dir, escaped, rng);
  }
  SurfaceHit z;
  if (!rays.intersect(origin, dir, 0.0f, kInf, z))
    return l + my.diffuse * shading.environmentLight(y, dir, true, rng);
  l += my.diffuse * shading.environmentLight(y, dir, false, rng);
  const SurfaceMaterial mz = shading.material(z);
  glm::vec3 lz = emitterLight ? mz.emission : glm::vec3(0.0f);
  lz += reflected(shading, z, mz, -dir, more - 1, emitterLight, rng);
  return l + my.diffuse * lz;
}

// One sample of the pixel's quantity (before the Alchemy transform).
glm::vec3 sampleQuantity(const Settings& s, const Shading& shading, const Primary& p, Rng& rng) {
  const RayScene& rays = shading.rays();
  const glm::vec3 origin = RayScene::spawnOrigin(p.hit);
  const glm::vec3 dir = cosineDirection(p.hit.shadingNormal, rng);
  switch (s.quantity) {
    case Quantity::AO:
      return glm::vec3(rays.occluded(origin, dir, 0.0f, s.radius) ? 0.0f : 1.0f);
    case Quantity::Obscurance: {
      const float tfar = s.membership == Membership::Exponential ? kInf : s.radius;
      SurfaceHit h;
      if (!rays.intersect(origin, dir, 0.0f, tfar, h)) return glm::vec3(1.0f);
      return glm::vec3(membership(s.membership, h.t, s.radius));
    }
    case Quantity::Alchemy: {
      SurfaceHit h;
      if (!rays.intersect(origin, dir, 0.0f, s.radius, h)) return glm::vec3(0.0f);
      return glm::vec3(alchemyFalloff(s.alchemy, h.t));
    }
    case Quantity::Direct: {
      const bool escaped = !rays.occluded(origin, dir, 0.0f, kInf);
      return p.base + p.material.diffuse * shading.environmentLight(p.hit, dir, escaped, rng);
    }
    case Quantity::DirectIndirect: {
      // Light from emissive surfaces: sampled on the emitters and, below, by the cosine-
      // sampled bounce, combined by multiple importance sampling (balance heuristic).
      const glm::vec3 emitted = p.material.diffuse == glm::vec3(0.0f) || !s.emitterLight
                                    ? glm::vec3(0.0f)
                                    : p.material.diffuse * shading.sampleEmitters(p.hit, rng);
      SurfaceHit y;
      if (!rays.intersect(origin, dir, 0.0f, kInf, y))
        return p.base + emitted +
               p.material.diffuse * shading.environmentLight(p.hit, dir, true, rng);
      const glm::vec3 sky = p.material.diffuse * shading.environmentLight(p.hit, dir, false, rng);
      // The radiance leaving y towards the pixel's point: its emission (MIS-weighted) plus
      // what it reflects: its direct light (lights with shadow rays, environment by one cosine
      // sample) and, with more bounces, the light of the further path (reflected()).
      const SurfaceMaterial my = shading.material(y);
      glm::vec3 ly(0.0f);
      if (my.emission != glm::vec3(0.0f) && s.emitterLight)
        ly += my.emission * shading.bsdfWeight(p.hit, dir, y, my.emission);
      ly += reflected(shading, y, my, -dir, s.bounces - 1, s.emitterLight, rng);
      return p.base + emitted + sky + p.material.diffuse * ly;
    }
    case Quantity::Depth:
    case Quantity::Normal:
    case Quantity::AOSplit:      // sampleAoSplit
    case Quantity::AlchemyDisk:  // sampleAlchemyDisk
      break;
  }
  return glm::vec3(0.0f);
}

// The camera as the screen-disk samples of AlchemyDisk need it (view space, double).
struct DiskCamera {
  glm::dmat4 view{1.0}, invView{1.0};
  bool orthographic = false;
  double znear = 0.0, zfar = 0.0;
};

// The camera ray through view-space point x: origin and direction in world space, the direction
// scaled so that the ray parameter is the view depth (the primary rays' convention).
void cameraRay(const DiskCamera& cam, const glm::dvec3& x, glm::dvec3& origin, glm::dvec3& dir) {
  if (cam.orthographic) {
    origin = glm::dvec3(cam.invView * glm::dvec4(x.x, x.y, 0.0, 1.0));
    dir = glm::dmat3(cam.invView) * glm::dvec3(0.0, 0.0, -1.0);
  } else {
    origin = glm::dvec3(cam.invView[3]);
    dir = glm::dmat3(cam.invView) * (x / -x.z);
  }
}

// One sample of the AlchemyDisk quantity (reference.h): 2 sigma f at a point uniform in radius
// and angle on the camera-facing disk of radius r through the primary hit.
float sampleAlchemyDisk(const Settings& s, const Shading& shading, const DiskCamera& cam,
                        const Primary& p, Rng& rng) {
  const AlchemyParams& a = s.alchemy;
  const glm::dvec3 c(cam.view * glm::dvec4(glm::dvec3(p.hit.position), 1.0));
  const double z = -c.z;
  const glm::dvec3 n = glm::normalize(glm::dmat3(cam.view) * glm::dvec3(p.hit.shadingNormal));
  const double rho = double(rng.uniform()) * s.radius;
  const double phi = double(rng.uniform()) * 6.28318530717958647692;
  const glm::dvec3 x = c + rho * glm::dvec3(std::cos(phi), std::sin(phi), 0.0);
  if (!(x.z < 0.0)) return 0.0f;  // guard: a point at or behind the eye (z > 0 already holds)
  glm::dvec3 origin, dir;
  cameraRay(cam, x, origin, dir);
  SurfaceHit h;
  if (!shading.rays().intersect(glm::vec3(origin), glm::vec3(dir), float(cam.znear),
                                float(cam.zfar), h))
    return 0.0f;  // sky: unoccluded
  const glm::dvec3 v = glm::dvec3(cam.view * glm::dvec4(glm::dvec3(h.position), 1.0)) - c;
  const double vv = glm::dot(v, v), r2 = double(s.radius) * s.radius;
  if (!(vv < r2)) return 0.0f;
  const double num = std::max(0.0, glm::dot(v, n) - double(a.bias) * z);
  const double u2 = double(a.u) * a.u;
  const double denom = std::max(u2, vv) + double(a.epsilon);
  return denom > 0.0 ? float(2.0 * double(a.sigma) * num / denom) : 0.0f;
}

// The camera and the depth layer (the primary hits) that the AO split classifies occluders
// against: what a single-layer depth buffer of the rasteriser holds.
struct DepthLayer {
  glm::dmat4 view{1.0}, proj{1.0};
  glm::dvec3 eye{0.0};
  uint32_t width = 1, height = 1;
  double znear = 0.0, zfar = 0.0;
  double relTolerance = 0.01, absTolerance = 0.0;  // |d - D| <= rel d + abs
  const std::vector<Primary>* primary = nullptr;
  std::vector<double> viewDepth;  // -view z of each pixel's primary hit (0 on sky)
};

enum class Occluder { Visible, Offscreen, Hidden, HiddenInFront };

// Where a surface point stands with respect to the camera's depth layer (see reference.h).
Occluder classifyOccluder(const DepthLayer& layer, const glm::vec3& point) {
  const glm::dvec3 x(point);
  const glm::dvec4 viewPos = layer.view * glm::dvec4(x, 1.0);
  const double d = -viewPos.z;
  if (!(d >= layer.znear && d <= layer.zfar)) return Occluder::Offscreen;
  const glm::dvec4 clip = layer.proj * viewPos;
  if (!(clip.w > 0.0)) return Occluder::Offscreen;
  const double nx = clip.x / clip.w, ny = clip.y / clip.w;
  if (!(std::abs(nx) <= 1.0 && std::abs(ny) <= 1.0)) return Occluder::Offscreen;
  const int W = int(layer.width), H = int(layer.height);
  const int ix = std::clamp(int(std::floor((nx + 1.0) * 0.5 * W)), 0, W - 1);
  const int iy = std::clamp(int(std::floor((ny + 1.0) * 0.5 * H)), 0, H - 1);
  const double tolerance = layer.relTolerance * d + layer.absTolerance;
  const glm::dvec3 u = x - layer.eye;  // the eye ray through x: view depth t d at eye + t u
  const double ulen = glm::length(u);
  // The pixel itself first, then its 8 neighbours.
  static constexpr int kOffsets[9][2] = {{0, 0}, {-1, -1}, {0, -1}, {1, -1}, {-1, 0},
                                         {1, 0}, {-1, 1},  {0, 1},  {1, 1}};
  for (const auto& o : kOffsets) {
    const int qx = ix + o[0], qy = iy + o[1];
    if (qx < 0 || qy < 0 || qx >= W || qy >= H) continue;
    const size_t q = size_t(qy) * layer.width + size_t(qx);
    const Primary& p = (*layer.primary)[q];
    if (!p.geometry) continue;
    if (std::abs(d - layer.viewDepth[q]) <= tolerance) return Occluder::Visible;
    // The pixel's surface extended by its tangent plane to where the eye ray through x meets it.
    const glm::dvec3 n(p.hit.geometricNormal);
    const double denom = glm::dot(u, n);
    if (std::abs(denom) > 1e-9 * ulen) {
      const double t = glm::dot(glm::dvec3(p.hit.position) - layer.eye, n) / denom;
      if (t > 0.0 && std::isfinite(t) && std::abs(d - t * d) <= tolerance) return Occluder::Visible;
    }
  }
  const size_t own = size_t(iy) * layer.width + size_t(ix);
  const bool behind = (*layer.primary)[own].geometry && d > layer.viewDepth[own];
  return behind ? Occluder::Hidden : Occluder::HiddenInFront;
}

struct SplitSample {
  glm::vec4 value{0.0f};  // open (AO_full), 1 - visible-occluded (AO_visible), f_off, f_hid
  bool visibleBehind = false, hiddenInFront = false;
};

// One sample of the AO split: the AO direction, its first hit within r classified; a first hit
// outside the depth layer lets the ray go on to look for a layer surface behind it within r.
SplitSample sampleAoSplit(const Settings& s, const Shading& shading, const DepthLayer& layer,
                          const Primary& p, Rng& rng) {
  constexpr int kMaxLayers = 64;  // surfaces followed along one ray (ends a pathological loop)
  const RayScene& rays = shading.rays();
  const glm::vec3 origin = RayScene::spawnOrigin(p.hit);
  const glm::vec3 dir = cosineDirection(p.hit.shadingNormal, rng);
  SplitSample out;
  SurfaceHit h;
  if (!rays.intersect(origin, dir, 0.0f, s.radius, h)) {
    out.value = glm::vec4(1.0f, 1.0f, 0.0f, 0.0f);
    return out;
  }
  const Occluder first = classifyOccluder(layer, h.position);
  if (first == Occluder::Visible) {
    out.value = glm::vec4(0.0f, 0.0f, 0.0f, 0.0f);
    return out;
  }
  for (int k = 0; k < kMaxLayers; ++k) {
    const float tnear = h.t + std::max(RayScene::offsetDistance(h), h.t * 1e-6f);
    if (!(tnear < s.radius) || !rays.intersect(origin, dir, tnear, s.radius, h)) break;
    if (classifyOccluder(layer, h.position) == Occluder::Visible) {
      out.value = glm::vec4(0.0f, 0.0f, 0.0f, 0.0f);
      out.visibleBehind = true;
      return out;
    }
  }
  if (first == Occluder::Offscreen) {
    out.value = glm::vec4(0.0f, 1.0f, 1.0f, 0.0f);
  } else {
    out.value = glm::vec4(0.0f, 1.0f, 0.0f, 1.0f);
    out.hiddenInFront = first == Occluder::HiddenInFront;
  }
  return out;
}

template <class F>
void parallelRows(unsigned threads, uint32_t rows, const F& f) {
  std::atomic<uint32_t> next{0};
  auto worker = [&] {
    for (uint32_t y = next.fetch_add(1); y < rows; y = next.fetch_add(1)) f(y);
  };
  std::vector<std::thread> pool;
  for (unsigned i = 1; i < std::min<unsigned>(threads, rows); ++i) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
}

void validate(const Settings& s) {
  if (s.width < 1 || s.height < 1 || s.width > 16384 || s.height > 16384)
    usage("image size must be 1..16384 pixels per side");
  const bool needsRadius = s.quantity == Quantity::AO || s.quantity == Quantity::Obscurance ||
                           s.quantity == Quantity::Alchemy || s.quantity == Quantity::AOSplit ||
                           s.quantity == Quantity::AlchemyDisk;
  if (needsRadius && !(s.radius > 0.0f && std::isfinite(s.radius)))
    usage("radius must be a positive finite number");
  if (s.spp < 1) usage("samples per pixel must be at least 1");
  if (s.bounces < 1 || s.bounces > kMaxBounces) usage("bounces must be 1..8");
  if (!(s.noiseTarget >= 0.0 && std::isfinite(s.noiseTarget)))
    usage("noise target must be a finite number >= 0");
  const AlchemyParams& a = s.alchemy;
  if (!(a.sigma >= 0.0f && std::isfinite(a.sigma)) || !(a.u >= 0.0f && std::isfinite(a.u)) ||
      !(a.epsilon >= 0.0f && std::isfinite(a.epsilon)) ||
      !(a.contrast > 0.0f && std::isfinite(a.contrast)) ||
      !(a.bias >= 0.0f && std::isfinite(a.bias)))
    usage("Alchemy parameters must be finite, sigma/u/epsilon/bias >= 0 and contrast > 0");
  // With u = 0 the falloff sigma t / (t^2 + epsilon) peaks at sigma / (2 sqrt(epsilon)):
  // epsilon = 0 makes it unbounded near t = 0 and the estimate's variance with it.
  if (s.quantity == Quantity::Alchemy && a.u == 0.0f && a.epsilon == 0.0f)
    usage("Alchemy epsilon must be > 0 when u = 0 (the falloff is unbounded at distance 0)");
  if (s.quantity == Quantity::AlchemyDisk && !(a.epsilon > 0.0f || a.u > 0.0f))
    usage("alchemy-disk needs epsilon > 0 or u > 0 (a tap at the pixel's own point is 0 / 0)");
  if (s.camera) {
    const glm::mat4& p = s.camera->proj;
    bool ok = true;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        ok = ok && std::isfinite(p[i][j]) && std::isfinite(s.camera->view[i][j]);
    if (!ok || !(s.camera->znear > 0.0f) || !(s.camera->zfar > s.camera->znear) ||
        !std::isfinite(s.camera->zfar))
      usage("camera override: matrices must be finite and 0 < znear < zfar");
    if (s.quantity == Quantity::AOSplit && p[3][3] != 0.0f)
      usage("ao-split needs a perspective camera");
  }
}

void setPixel(ImageRGBA32F& img, size_t i, const glm::vec3& v, float a) {
  img.pixels[i * 4 + 0] = v.x;
  img.pixels[i * 4 + 1] = v.y;
  img.pixels[i * 4 + 2] = v.z;
  img.pixels[i * 4 + 3] = a;
}

ImageRGBA32F blank(uint32_t w, uint32_t h) {
  return ImageRGBA32F{int(w), int(h), std::vector<float>(size_t(w) * h * 4, 0.0f)};
}

}  // namespace

Quantity parseQuantity(const std::string& name) {
  for (Quantity q : {Quantity::AO, Quantity::Obscurance, Quantity::Alchemy, Quantity::Direct,
                     Quantity::DirectIndirect, Quantity::Depth, Quantity::Normal, Quantity::AOSplit,
                     Quantity::AlchemyDisk})
    if (name == quantityName(q)) return q;
  usage("unknown quantity '" + name +
        "' (ao, obscurance, alchemy, direct, direct+indirect, depth, normal, ao-split, "
        "alchemy-disk)");
}

const char* quantityName(Quantity q) {
  switch (q) {
    case Quantity::AO:
      return "ao";
    case Quantity::Obscurance:
      return "obscurance";
    case Quantity::Alchemy:
      return "alchemy";
    case Quantity::Direct:
      return "direct";
    case Quantity::DirectIndirect:
      return "direct+indirect";
    case Quantity::Depth:
      return "depth";
    case Quantity::Normal:
      return "normal";
    case Quantity::AOSplit:
      return "ao-split";
    case Quantity::AlchemyDisk:
      return "alchemy-disk";
  }
  return "?";
}

Membership parseMembership(const std::string& name) {
  for (Membership m : {Membership::Sqrt, Membership::Linear, Membership::Smoothstep,
                       Membership::Step, Membership::Exponential})
    if (name == membershipName(m)) return m;
  usage("unknown membership function '" + name + "' (sqrt, linear, smoothstep, step, exp)");
}

const char* membershipName(Membership m) {
  switch (m) {
    case Membership::Sqrt:
      return "sqrt";
    case Membership::Linear:
      return "linear";
    case Membership::Smoothstep:
      return "smoothstep";
    case Membership::Step:
      return "step";
    case Membership::Exponential:
      return "exp";
  }
  return "?";
}

glm::vec3 environmentRadiance(const Environment& env, const glm::vec3& dir) {
  return environmentLookup(env, dir);  // sky, constant or equirect map (gi/environment.h)
}

Result render(const Scene& scene, const Settings& settings) {
  validate(settings);
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  const uint32_t W = settings.width, H = settings.height;
  const size_t N = size_t(W) * H;
  const unsigned threads =
      settings.threads > 0 ? settings.threads : std::max(1u, std::thread::hardware_concurrency());

  RayScene rays(scene);
  Shading shading(scene, rays);
  Result result;
  result.triangles = rays.triangleCount();
  result.camera = settings.camera ? *settings.camera : activeCamera(scene, float(W) / float(H));
  const CameraView& cam = result.camera;
  // Primary rays in double precision from the same matrices the rasteriser uses.
  const glm::dmat4 proj(cam.proj), view(cam.view);
  const glm::dmat4 invProj = glm::inverse(proj), invView = glm::inverse(view);
  const glm::dvec3 eye(invView[3]);
  const double znear = cam.znear, zfar = cam.zfar;
  // An orthographic projection's w row is (0, 0, 0, 1): parallel rays along the view axis.
  const bool orthographic = cam.proj[3][3] != 0.0f;

  result.value = blank(W, H);
  result.stdError = blank(W, H);
  result.depth = blank(W, H);
  result.normal = blank(W, H);
  result.position = blank(W, H);
  std::vector<Primary> primary(N);
  std::vector<glm::vec3> skyRadiance(N, glm::vec3(0.0f));
  const bool lighting =
      settings.quantity == Quantity::Direct || settings.quantity == Quantity::DirectIndirect;

  parallelRows(threads, H, [&](uint32_t y) {
    for (uint32_t x = 0; x < W; ++x) {
      const size_t i = size_t(y) * W + x;
      const glm::dvec2 ndc = glm::dvec2((x + 0.5) / W, (y + 0.5) / H) * 2.0 - 1.0;
      // The near-plane point (reverse-Z depth 1) through the pixel centre, scaled to view z = -1:
      // the ray parameter is then the view-space depth, and [znear, zfar] is what is rasterised.
      glm::dvec4 nearPoint = invProj * glm::dvec4(ndc, 1.0, 1.0);
      glm::dvec3 dirView = glm::dvec3(nearPoint) / nearPoint.w;
      glm::dvec3 origin = eye;
      if (orthographic) {  // from the view plane z = 0 through the near-plane point
        origin = glm::dvec3(invView * glm::dvec4(dirView.x, dirView.y, 0.0, 1.0));
        dirView = glm::dvec3(0.0, 0.0, -1.0);
      } else {
        dirView /= -dirView.z;
      }
      const glm::vec3 dirWorld(glm::dmat3(invView) * dirView);
      skyRadiance[i] = shading.environment(safeNormalize(dirWorld, glm::vec3(0, 0, -1)));
      Primary& p = primary[i];
      p.geometry = rays.intersect(glm::vec3(origin), dirWorld, float(znear), float(zfar), p.hit);
      if (!p.geometry) continue;
      const glm::dvec4 viewPos = view * glm::dvec4(glm::dvec3(p.hit.position), 1.0);
      const glm::dvec4 clip = proj * viewPos;
      const double depth = clip.w != 0.0 ? clip.z / clip.w : 0.0;
      setPixel(result.depth, i, glm::vec3(float(depth), float(viewPos.z), 1.0f), 1.0f);
      setPixel(result.normal, i, glm::vec3(glm::dmat3(view) * glm::dvec3(p.hit.shadingNormal)),
               1.0f);
      setPixel(result.position, i, p.hit.position, 1.0f);
      if (lighting) {
        p.material = shading.material(p.hit);
        // Towards the eye, as the lighting pass's v = -position in view space (orthographic
        // cameras too).
        const glm::vec3 toEye = safeNormalize(glm::vec3(eye) - p.hit.position, -dirWorld);
        p.base = p.material.emission + shading.directLights(p.hit, p.material, toEye);
      }
    }
  });
  for (const Primary& p : primary) result.geometryPixels += p.geometry ? 1 : 0;

  if (settings.quantity == Quantity::Depth || settings.quantity == Quantity::Normal) {
    result.value = settings.quantity == Quantity::Depth ? result.depth : result.normal;
    for (size_t i = 0; i < N; ++i) result.stdError.pixels[i * 4 + 3] = primary[i].geometry;
    result.spp = 1;
    result.seconds = elapsed();
    if (settings.progress) settings.progress({1, 0.0, result.seconds});
    return result;
  }

  // The AO split classifies occluders against the depth layer of the primary hits above.
  const bool aoSplit = settings.quantity == Quantity::AOSplit;
  DepthLayer layer;
  std::vector<uint32_t> visibleBehind, hiddenInFront;  // per pixel, AOSplit diagnostics
  if (aoSplit) {
    layer.view = view;
    layer.proj = proj;
    layer.eye = eye;
    layer.width = W;
    layer.height = H;
    layer.znear = znear;
    layer.zfar = zfar;
    layer.absTolerance = 1e-3 * double(settings.radius);
    layer.primary = &primary;
    layer.viewDepth.assign(N, 0.0);
    for (size_t i = 0; i < N; ++i)
      if (primary[i].geometry) layer.viewDepth[i] = -double(result.depth.pixels[i * 4 + 1]);
    result.split = blank(W, H);
    result.splitStdError = blank(W, H);
    visibleBehind.assign(N, 0);
    hiddenInFront.assign(N, 0);
  }

  // Progressive estimation: per-pixel running mean and M2 (Welford) in double, extended in
  // passes of growing size until the sample budget or the noise target is reached. Four
  // channels: the quantity's rgb (AO_full, AO_visible, f_off, f_hid for the AO split).
  constexpr int C = 4;
  std::vector<double> mean(N * C, 0.0), m2(N * C, 0.0);
  const bool alchemy =
      settings.quantity == Quantity::Alchemy || settings.quantity == Quantity::AlchemyDisk;
  const bool alchemyDisk = settings.quantity == Quantity::AlchemyDisk;
  DiskCamera diskCamera;
  diskCamera.view = view;
  diskCamera.invView = invView;
  diskCamera.orthographic = orthographic;
  diskCamera.znear = znear;
  diskCamera.zfar = zfar;
  const AlchemyParams& ap = settings.alchemy;
  uint32_t done = 0;
  auto standardError = [&](size_t i, int c) {
    const double var = done > 1 ? m2[i * C + c] / double(done - 1) : 0.0;
    return std::sqrt(std::max(var, 0.0) / double(done));
  };
  auto finiteFloat = [](double v) { return std::isfinite(v) ? float(v) : 0.0f; };
  auto finishPixel = [&](size_t i) {
    // Value and standard error of the pixel after `done` samples.
    glm::vec3 value, se;
    if (aoSplit) {
      value = glm::vec3(finiteFloat(mean[i * C]));
      se = glm::vec3(finiteFloat(standardError(i, 0)));
      setPixel(result.split, i,
               glm::vec3(finiteFloat(mean[i * C + 1]), finiteFloat(mean[i * C + 2]),
                         finiteFloat(mean[i * C + 3])),
               1.0f);
      setPixel(result.splitStdError, i,
               glm::vec3(finiteFloat(standardError(i, 1)), finiteFloat(standardError(i, 2)),
                         finiteFloat(standardError(i, 3))),
               1.0f);
    } else {
      for (int c = 0; c < 3; ++c) {
        const double m = mean[i * C + c];
        double err = standardError(i, c);
        double v = m;
        if (alchemy) {
          const double base = 1.0 - m;
          v = base > 0.0 ? std::pow(base, double(ap.contrast)) : 0.0;
          if (ap.contrast != 1.0f)
            err *=
                base > 0.0 ? std::min(ap.contrast * std::pow(base, ap.contrast - 1.0), 1e6) : 0.0;
        }
        value[c] = finiteFloat(v);
        se[c] = finiteFloat(err);
      }
    }
    setPixel(result.value, i, value, 1.0f);
    setPixel(result.stdError, i, se, 1.0f);
    return (double(se.x) + se.y + se.z) / 3.0;
  };

  uint32_t target = std::min(settings.spp, std::max(settings.minSpp, 1u));
  while (true) {
    const uint32_t from = done, to = target;
    parallelRows(threads, H, [&](uint32_t y) {
      for (uint32_t x = 0; x < W; ++x) {
        const size_t i = size_t(y) * W + x;
        const Primary& p = primary[i];
        if (!p.geometry) continue;
        for (uint32_t s = from; s < to; ++s) {
          Rng rng = Rng::forSample(settings.seed, i, s);
          glm::vec4 v(0.0f);
          if (aoSplit) {
            const SplitSample split = sampleAoSplit(settings, shading, layer, p, rng);
            v = split.value;
            visibleBehind[i] += split.visibleBehind;
            hiddenInFront[i] += split.hiddenInFront;
          } else if (alchemyDisk) {
            v = glm::vec4(sampleAlchemyDisk(settings, shading, diskCamera, p, rng));
            if (!std::isfinite(v.x)) v = glm::vec4(0.0f);  // guard: never let a NaN in
          } else {
            v = glm::vec4(sampleQuantity(settings, shading, p, rng), 0.0f);
            if (!finite(glm::vec3(v))) v = glm::vec4(0.0f);  // guard: never let a NaN in
          }
          const double n = double(s) + 1.0;
          for (int c = 0; c < C; ++c) {
            const double d = double(v[c]) - mean[i * C + c];
            mean[i * C + c] += d / n;
            m2[i * C + c] += d * (double(v[c]) - mean[i * C + c]);
          }
        }
      }
    });
    done = to;
    double sumError = 0.0;
    for (size_t i = 0; i < N; ++i)
      if (primary[i].geometry) sumError += finishPixel(i);
    result.meanStdError = result.geometryPixels > 0 ? sumError / double(result.geometryPixels) : 0;
    if (settings.progress) settings.progress({done, result.meanStdError, elapsed()});
    if (done >= settings.spp) break;
    if (settings.noiseTarget > 0.0 && done >= 2 && result.meanStdError <= settings.noiseTarget)
      break;
    if (result.geometryPixels == 0) break;
    target = std::min<uint32_t>(settings.spp, done + std::max(done / 2, 1u));
  }

  // Sky pixels: fully open for the occlusion quantities, the environment for lighting.
  for (size_t i = 0; i < N; ++i) {
    if (primary[i].geometry) continue;
    setPixel(result.value, i, lighting ? finiteOrZero(skyRadiance[i]) : glm::vec3(1.0f), 0.0f);
    setPixel(result.stdError, i, glm::vec3(0.0f), 0.0f);
    if (aoSplit) {
      setPixel(result.split, i, glm::vec3(1.0f, 0.0f, 0.0f), 0.0f);
      setPixel(result.splitStdError, i, glm::vec3(0.0f), 0.0f);
    }
  }
  if (aoSplit)
    for (size_t i = 0; i < N; ++i) {
      if (!primary[i].geometry) continue;
      // Occluded samples: 1 - AO_full of `done`, an integer count up to rounding.
      result.splitOccluded += uint64_t(std::llround((1.0 - mean[i * C]) * double(done)));
      result.splitVisibleBehind += visibleBehind[i];
      result.splitHiddenInFront += hiddenInFront[i];
    }
  result.spp = done;
  result.seconds = elapsed();
  return result;
}

AoSplitSummary summarizeAoSplit(const Result& r) {
  AoSplitSummary s;
  const size_t n = size_t(r.value.width) * size_t(r.value.height);
  if (r.split.pixels.size() != n * 4 || r.value.pixels.size() != n * 4) return s;
  double sumFull = 0.0, sumVisible = 0.0, sumOff = 0.0, sumHidden = 0.0, se = 0.0;
  for (size_t i = 0; i < n; ++i) {
    if (!(r.split.pixels[i * 4 + 3] > 0.5f)) continue;
    const double full = r.value.pixels[i * 4], visible = r.split.pixels[i * 4];
    sumFull += full;
    sumVisible += visible;
    sumOff += r.split.pixels[i * 4 + 1];
    sumHidden += r.split.pixels[i * 4 + 2];
    se += (visible - full) * (visible - full);
    ++s.pixels;
  }
  if (s.pixels == 0) return s;
  const double count = double(s.pixels);
  s.aoFull = sumFull / count;
  s.aoVisible = sumVisible / count;
  s.offscreen = sumOff / count;
  s.hidden = sumHidden / count;
  s.visible = 1.0 - s.aoVisible;
  s.limitNrmse = std::sqrt(se / count) / (s.aoFull > 1e-8 ? s.aoFull : 1.0);
  return s;
}

ImageRGBA8 previewChannel(const ImageRGBA32F& image, int c) {
  ImageRGBA8 out{image.width, image.height, std::vector<uint8_t>(image.pixels.size(), 255)};
  c = std::clamp(c, 0, 3);
  for (size_t i = 0; i + 3 < image.pixels.size(); i += 4) {
    float v = image.pixels[i + size_t(c)];
    if (!std::isfinite(v)) v = 0.0f;
    const uint8_t g = uint8_t(std::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f);
    out.pixels[i] = out.pixels[i + 1] = out.pixels[i + 2] = g;
  }
  return out;
}

ImageRGBA8 preview(const ImageRGBA32F& value, Quantity q, float exposure) {
  ImageRGBA8 out{value.width, value.height, std::vector<uint8_t>(value.pixels.size(), 255)};
  auto aces = [](float x) {
    return std::clamp((x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f), 0.0f, 1.0f);
  };
  auto srgb = [](float c) {
    return c > 0.0031308f ? 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f : c * 12.92f;
  };
  const bool tonemap = q == Quantity::Direct || q == Quantity::DirectIndirect;
  for (size_t i = 0; i + 3 < value.pixels.size(); i += 4) {
    for (int c = 0; c < 3; ++c) {
      float v = q == Quantity::Depth ? value.pixels[i] : value.pixels[i + c];
      if (!std::isfinite(v)) v = 0.0f;
      if (tonemap) v = srgb(aces(std::max(v * exposure, 0.0f)));
      if (q == Quantity::Normal) v = v * 0.5f + 0.5f;
      out.pixels[i + c] = uint8_t(std::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f);
    }
  }
  return out;
}

}  // namespace gi::reference
