// Keyframe sampling, Scene::animate, morph targets and CPU reference skinning.
#include "gi/animation.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace gi {
namespace {

glm::quat quatAt(const float* v) {
  return glm::quat(v[3], v[0], v[1], v[2]);  // stored x, y, z, w
}

// Slerp across the short arc (q and -q are the same rotation); falls back to normalised lerp
// when the two are nearly equal.
glm::quat slerpShort(glm::quat a, glm::quat b, float t) {
  float d = glm::dot(a, b);
  if (d < 0.0f) {
    b = -b;
    d = -d;
  }
  if (d > 0.9995f) return glm::normalize(a * (1.0f - t) + b * t);
  const float theta = std::acos(std::min(d, 1.0f));
  const float s = std::sin(theta);
  return a * (std::sin((1.0f - t) * theta) / s) + b * (std::sin(t * theta) / s);
}

glm::vec3 finiteOr(const glm::vec3& v, const glm::vec3& fallback) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) ? v : fallback;
}

}  // namespace

double loopTime(double time, double duration) {
  if (!(duration > 0.0) || !std::isfinite(time)) return 0.0;
  double t = std::fmod(time, duration);
  if (t < 0.0) t += duration;
  return t;
}

std::vector<float> sampleAnimation(const AnimationSampler& s, double time, bool rotation) {
  const size_t n = s.times.size();
  const size_t c = size_t(std::max(s.components, 1));
  std::vector<float> out(c, 0.0f);
  if (n == 0) return out;
  const bool cubic = s.interpolation == Interpolation::CubicSpline;
  const size_t keySize = cubic ? 3 * c : c;
  // The value (not the tangents) of key k.
  auto value = [&](size_t k) { return &s.values[k * keySize + (cubic ? c : 0)]; };
  auto finish = [&](std::vector<float> v) {
    if (rotation && c == 4) {
      glm::quat q = quatAt(v.data());
      const float len = glm::length(q);
      q = len > 1e-12f && std::isfinite(len) ? q / len : glm::quat(1, 0, 0, 0);
      v = {q.x, q.y, q.z, q.w};
    }
    return v;
  };
  if (time <= double(s.times[0]) || n == 1) return finish({value(0), value(0) + c});
  if (time >= double(s.times[n - 1])) return finish({value(n - 1), value(n - 1) + c});
  // Key k with times[k] <= time < times[k + 1].
  const size_t k =
      size_t(std::upper_bound(s.times.begin(), s.times.end(), float(time)) - s.times.begin()) - 1;
  const double t0 = s.times[k], t1 = s.times[k + 1];
  const double dt = t1 - t0;
  const float u = float(std::clamp((time - t0) / dt, 0.0, 1.0));
  switch (s.interpolation) {
    case Interpolation::Step:
      return finish({value(k), value(k) + c});
    case Interpolation::Linear:
      if (rotation && c == 4) {
        const glm::quat q = slerpShort(quatAt(value(k)), quatAt(value(k + 1)), u);
        return finish({q.x, q.y, q.z, q.w});
      }
      for (size_t i = 0; i < c; ++i) out[i] = value(k)[i] * (1.0f - u) + value(k + 1)[i] * u;
      return finish(out);
    case Interpolation::CubicSpline: {
      // glTF Appendix C: p(u) = (2u^3-3u^2+1) v0 + (u^3-2u^2+u) dt b0 + (-2u^3+3u^2) v1
      //                          + (u^3-u^2) dt a1, with b0 the out-tangent of key k and a1 the
      //                          in-tangent of key k+1.
      const float u2 = u * u, u3 = u2 * u, d = float(dt);
      const float h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2,
                  h11 = u3 - u2;
      const float* v0 = value(k);
      const float* b0 = &s.values[k * keySize + 2 * c];
      const float* v1 = value(k + 1);
      const float* a1 = &s.values[(k + 1) * keySize];
      for (size_t i = 0; i < c; ++i)
        out[i] = h00 * v0[i] + h10 * d * b0[i] + h01 * v1[i] + h11 * d * a1[i];
      return finish(out);
    }
  }
  return out;
}

void Scene::animate(double time, int clip) {
  for (size_t ci = 0; ci < animations.size(); ++ci) {
    if (clip >= 0 && size_t(clip) != ci) continue;
    const AnimationClip& a = animations[ci];
    const double t = loopTime(time, a.duration);
    for (const AnimationChannel& ch : a.channels) {
      if (ch.node < 0 || size_t(ch.node) >= nodes.size() || ch.sampler < 0 ||
          size_t(ch.sampler) >= a.samplers.size())
        continue;
      Node& node = nodes[ch.node];
      const std::vector<float> v =
          sampleAnimation(a.samplers[ch.sampler], t, ch.path == AnimationPath::Rotation);
      switch (ch.path) {
        case AnimationPath::Translation:
          if (v.size() == 3) node.translation = finiteOr({v[0], v[1], v[2]}, node.translation);
          node.hasTRS = true;
          break;
        case AnimationPath::Scale:
          if (v.size() == 3) node.scale = finiteOr({v[0], v[1], v[2]}, node.scale);
          node.hasTRS = true;
          break;
        case AnimationPath::Rotation:
          if (v.size() == 4) node.rotation = glm::quat(v[3], v[0], v[1], v[2]);
          node.hasTRS = true;
          break;
        case AnimationPath::Weights:
          node.morphWeights = v;
          for (float& w : node.morphWeights)
            if (!std::isfinite(w)) w = 0.0f;
          break;
      }
    }
  }
  for (Node& node : nodes)
    if (node.hasTRS)
      node.local = glm::translate(glm::mat4(1.0f), node.translation) *
                   glm::mat4_cast(node.rotation) * glm::scale(glm::mat4(1.0f), node.scale);
  updateWorldTransforms();
}

std::vector<glm::mat4> jointMatrices(const Scene& scene, int nodeIndex) {
  const Node& node = scene.nodes.at(size_t(nodeIndex));
  if (node.skin < 0 || size_t(node.skin) >= scene.skins.size()) return {};
  const Skin& skin = scene.skins[node.skin];
  const glm::mat4 toMesh = glm::inverse(node.world);
  std::vector<glm::mat4> out(skin.joints.size(), glm::mat4(1.0f));
  for (size_t j = 0; j < skin.joints.size(); ++j) {
    const int joint = skin.joints[j];
    if (joint < 0 || size_t(joint) >= scene.nodes.size()) continue;
    const glm::mat4 ibm =
        j < skin.inverseBindMatrices.size() ? skin.inverseBindMatrices[j] : glm::mat4(1.0f);
    out[j] = toMesh * scene.nodes[joint].world * ibm;
  }
  return out;
}

glm::mat4 blendJoints(const std::vector<glm::mat4>& joints, const glm::uvec4& index,
                      const glm::vec4& weight) {
  glm::mat4 m(0.0f);
  float sum = 0.0f;
  for (int i = 0; i < 4; ++i) {
    const float w = weight[i];
    if (!(w > 0.0f) || !std::isfinite(w) || index[i] >= joints.size()) continue;
    m += joints[index[i]] * w;
    sum += w;
  }
  if (!(sum > 1e-8f) || !std::isfinite(sum)) return glm::mat4(1.0f);
  return m * (1.0f / sum);
}

glm::mat3 cofactor3(const glm::mat4& m) {
  const glm::vec3 a(m[0]), b(m[1]), c(m[2]);
  glm::mat3 cof(glm::cross(b, c), glm::cross(c, a), glm::cross(a, b));
  if (glm::dot(a, glm::cross(b, c)) < 0.0f) cof = -cof;
  return cof;
}

std::vector<Vertex> skinVertices(const Mesh& mesh, const std::vector<Vertex>& rest,
                                 const std::vector<glm::mat4>& joints) {
  std::vector<Vertex> out = rest;
  if (!mesh.skinned() || rest.size() != mesh.joints.size()) return out;
  for (size_t v = 0; v < out.size(); ++v) {
    const glm::mat4 m = blendJoints(joints, mesh.joints[v], mesh.weights[v]);
    const glm::vec3 p = glm::vec3(m * glm::vec4(rest[v].position, 1.0f));
    out[v].position = finiteOr(p, rest[v].position);
    const glm::vec3 n = cofactor3(m) * rest[v].normal;
    const float len2 = glm::dot(n, n);
    out[v].normal = len2 > 1e-30f && std::isfinite(len2) ? n / std::sqrt(len2) : rest[v].normal;
  }
  return out;
}

std::vector<Vertex> morphVertices(const Mesh& mesh, const std::vector<float>& weights) {
  std::vector<Vertex> out = mesh.vertices;
  if (mesh.morphTargets.empty()) return out;
  bool any = false;
  for (size_t t = 0; t < mesh.morphTargets.size() && t < weights.size(); ++t) {
    const float w = weights[t];
    if (w == 0.0f || !std::isfinite(w)) continue;
    any = true;
    const MorphTarget& target = mesh.morphTargets[t];
    for (size_t v = 0; v < out.size() && v < target.positionDeltas.size(); ++v)
      out[v].position += w * target.positionDeltas[v];
    for (size_t v = 0; v < out.size() && v < target.normalDeltas.size(); ++v)
      out[v].normal += w * target.normalDeltas[v];
  }
  if (any)
    for (size_t v = 0; v < out.size(); ++v) {
      const float len2 = glm::dot(out[v].normal, out[v].normal);
      out[v].normal = len2 > 1e-30f && std::isfinite(len2) ? out[v].normal / std::sqrt(len2)
                                                           : mesh.vertices[v].normal;
    }
  return out;
}

}  // namespace gi
