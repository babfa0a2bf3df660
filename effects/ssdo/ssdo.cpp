// Screen-space directional occlusion with one indirect bounce (Ritschel, Grosch, Seidel 2009;
// seed 000; README.md). Four dispatches: per pixel what a tap reads (1/z, normal, sender
// radiance: ssdo_surface.comp), the samples (ssdo.comp), a geometry-aware separable blur whose
// y half writes the outputs (ssdo_blur_x.comp, ssdo_resolve.comp; ssdo_resolve_ambient.comp
// without the bounce). Publishes "ambient" (alpha 2: per unit diffuse albedo, replaces the
// engine's environment x AO term) and "indirect" (x the diffuse albedo, added).
// Depth peeling (seed 000 §4): `layers` - 1 more depth layers (2 by default, as the issue and
// the paper's Fig. 5 ask; 1 turns it off) peeled through the engine's layered-depth draw
// (passes ssdo_peel, ssdo_peel2, ssdo_peel3; layers 2 and 3 packed by ssdo_layers.comp).
// Optional, only built when asked: `cameras` low-resolution
// views whose G-buffers add occluders and senders (passes ssdo_cameras, ssdo_camera_surface).
// Optional (seed 000 §5, `contact_shadows`): the contact shadows the shadow-map bias removes
// (pass ssdo_contact, ssdo_contact.comp), applied to the lights SSDO publishes with the bounce,
// or published as the lighting pass's "contact_shadow" without it.
// With the bounce the senders need this frame's direct light, so ssdo_surface sums the lights
// as the lighting pass would and publishes that as "direct_light": the lighting pass uses it
// instead of summing them a second time.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "gi/effect.h"
#include "gi/effect_registry.h"
#include "gi/effect_shader.h"
#include "gi/lights.h"
#include "gi/lit_surface.h"
#include "gi/uniform_block.h"
#include "gi/vk/pipeline.h"
#include "gi/vk/resources.h"
#include "ssdo.comp.h"                  // const uint32_t ssdo_comp[]
#include "ssdo_blur_x.comp.h"           // const uint32_t ssdo_blur_x_comp[]
#include "ssdo_contact.comp.h"          // const uint32_t ssdo_contact_comp[]
#include "ssdo_depth.comp.h"            // const uint32_t ssdo_depth_comp[]
#include "ssdo_env_samples.comp.h"      // const uint32_t ssdo_env_samples_comp[]
#include "ssdo_layers.comp.h"           // const uint32_t ssdo_layers_comp[]
#include "ssdo_resolve.comp.h"          // const uint32_t ssdo_resolve_comp[]
#include "ssdo_resolve_ambient.comp.h"  // const uint32_t ssdo_resolve_ambient_comp[]
#include "ssdo_samples.h"
#include "ssdo_surface.comp.h"  // const uint32_t ssdo_surface_comp[]

namespace {

namespace res = gi::resources;
using gi::SettingType;

// Surface and raw texels pack four 32-bit words each (ssdo_common.glsl): one fetch per tap.
constexpr VkFormat kPackedFormat = VK_FORMAT_R32G32B32A32_UINT;
constexpr VkFormat kOutFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat kLayersFormat = VK_FORMAT_R32_UINT;  // layers 2 and 3: two half 1 / z
constexpr uint32_t kGroupX = 32, kGroupY = 16;          // local_size of every SSDO shader
constexpr int kMaxContactSamples = 16;

// A pipeline of one of the SSDO shaders; those that read ssdo_common.glsl's SsdoParams check it
// against gi::ssdo::Uniforms.
template <size_t N>
gi::vk::ComputeDesc shader(const char* name, const uint32_t (&words)[N],
                           std::vector<uint32_t> constants, bool readsParams = true) {
  using gi::ssdo::Uniforms;
  gi::vk::ComputeDesc d =
      gi::computeShader(std::string("ssdo: ") + name, words, std::move(constants));
  if (readsParams)
    d.blocks.uniforms = {
        {"ssdo", GI_CPP_BLOCK(Uniforms, radius, bias, bounceScale, distanceClamp2, blurTolerance,
                              blurMinCos, pad0, pad1, cameras, samples)}};
  return d;
}

// Bit masks of the light types present and of those with shadow maps (1 directional, 2 point,
// 4 spot), as the lighting pass's specialization constants.
std::array<uint32_t, 2> lightMasks(const std::vector<gi::LightInfo>& lights) {
  std::array<uint32_t, 2> m{0, 0};
  for (const gi::LightInfo& l : lights) {
    const uint32_t bit = 1u << uint32_t(l.type);
    m[0] |= bit;
    if (l.shadowLayer >= 0) m[1] |= bit;
  }
  return m;
}

class SsdoEffect : public gi::Effect {
 public:
  gi::EffectInfo info() const override {
    return {.name = "ssdo",
            .version = "1.0",
            .description =
                "screen-space directional occlusion of the environment with one indirect bounce "
                "(Ritschel et al. 2009; 16 interleaved sample sets, geometry-aware blur)",
            .stage = gi::EffectStage::BeforeLighting,
            .reads = {res::kDepth, res::kGBuffer, res::kLights, res::kShadowViews, res::kShadowMaps,
                      res::kEnvironmentMap, res::kEnvironmentSampling},
            .writes = {res::kAmbient, res::kIndirect, res::kContactShadow, res::kDirectLight},
            .debugView = res::kAmbient,
            .estimates = gi::GroundTruth::IndirectLight,
            .range = "radius"};
  }

  std::vector<gi::SettingDesc> settings() const override {
    return {
        gi::SettingDesc::length("radius", 0.5, 1e-6, 1e9,
                                "world-space length r_max of the sample steps (and the range "
                                "beyond which an occluder is ignored)"),
        gi::SettingDesc::samples(
            "samples", 12, 1, gi::ssdo::kMaxSamples,
            "samples N per pixel (a specialization constant: the loop unrolls)", true),
        {"pattern_sets", SettingType::Int, 16, 1, gi::ssdo::kPhases,
         "M precomputed sample sets spread over the 4x4 pixel pattern (16: every phase its "
         "own set; the blur averages them)",
         false},
        {"bounce", SettingType::Bool, 1, 0, 1,
         "one indirect bounce from the occluding samples (off: directional occlusion only, "
         "\"indirect\" is 0)",
         true},
        {"bounce_strength", SettingType::Float, 1.0, 0.0, 16.0,
         "scales the sender area A_s = pi r_max^2 / N", false},
        gi::SettingDesc::length("distance_clamp", 0.1, 1e-6, 1e9,
                                "bounce guard: the sender distance d is clamped to at least "
                                "this (1 / max(d^2, d_min^2))"),
        {"blur_radius", SettingType::Int, 2, 0, gi::ssdo::kMaxBlurRadius,
         "geometry-aware blur radius in pixels (0: none; even radii cancel the 4x4 pattern)", true},
        {"blur_normals", SettingType::Bool, 1, 0, 1,
         "the blur also rejects neighbours whose normal differs by more than acos(0.8) "
         "(off: the tangent-plane depth test alone, which lets creases blend over the radius)",
         true},
        {"layers", SettingType::Int, 2, 1, gi::ssdo::kMaxLayers,
         "depth layers (1: the G-buffer's alone; 2..4: depth peeling, layers - 1 peel passes; a "
         "sample is blocked only inside the solid intervals [layer 0, layer 1] and [layer 2, layer "
         "3]: thin objects "
         "stop shadowing what is behind them, and 3..4 see an occluder behind another one)",
         true},
        {"cameras", SettingType::Int, 0, 0, gi::ssdo::kMaxCameras,
         "additional low-resolution cameras (right, left, above, below the viewer, aimed at the "
         "centre of interest) whose G-buffers add occluders and senders the main view misses",
         true},
        {"camera_resolution", SettingType::Float, 0.5, 0.125, 1.0,
         "resolution of the additional cameras relative to the output", true},
        {"camera_displacement", SettingType::Float, 0.5, 0.0, 4.0,
         "distance of the additional cameras from the viewer, in radii of the scene's bounding "
         "sphere",
         false},
        gi::SettingDesc::enumeration(
            "environment_sampling", {"sh9", "map", "mis"}, 0,
            "an equirect map's radiance per sample direction: its SH9 (smooth, cheapest), the "
            "map itself over the cosine samples, or the map with half the samples drawn from the "
            "engine's importance sampling of it (multiple importance sampling: sharp, bright "
            "features such as a sun)",
            true),
        {"contact_shadows", SettingType::Bool, 0, 0, 1,
         "screen-space contact shadows for the first four shadow-casting lights: restores the "
         "shadow the shadow-map bias removes next to contacts (pass ssdo_contact; applied to "
         "the published \"direct_light\" with the bounce, published as \"contact_shadow\" "
         "without it)",
         true},
        gi::SettingDesc::samples("contact_samples", 4, 1, kMaxContactSamples,
                                 "samples per pixel and light on the bias segment toward the "
                                 "light (a specialization constant: the loop unrolls)",
                                 true),
    };
  }

  void prepare(gi::EffectContext& ctx, const gi::SettingValues& settings) override {
    gi::vk::Context& vk = ctx.vulkan();
    vk.requireWorkgroup(kGroupX, kGroupY, "ssdo");
    bounce_ = settings.flag("bounce");
    samples_ = uint32_t(std::clamp(settings.integer("samples"), 1, gi::ssdo::kMaxSamples));
    layers_ = uint32_t(std::clamp(settings.integer("layers"), 1, gi::ssdo::kMaxLayers));
    cameras_ = uint32_t(std::clamp(settings.integer("cameras"), 0, gi::ssdo::kMaxCameras));
    environmentSampling_ = uint32_t(std::clamp(settings.integer("environment_sampling"), 0, 2));
    contact_ = settings.flag("contact_shadows");
    contactSamples_ =
        uint32_t(std::clamp(settings.integer("contact_samples"), 1, kMaxContactSamples));
    contactMasks_.reset();  // the sample count may have changed: rebuilt on first use
    if (!depthInput()) buildSurface(ctx, lightMasks(ctx.lights()));
    buildSsdo(ctx, environmentKind(ctx.frame()));
    while (views_.size() < cameras_) views_.push_back(ctx.createView());
    // The blur's radius, whether it carries the bounce term and tests normals.
    const std::vector<uint32_t> blurConstants = {
        uint32_t(std::clamp(settings.integer("blur_radius"), 0, gi::ssdo::kMaxBlurRadius)),
        bounce_ ? 1u : 0u, settings.flag("blur_normals") ? 1u : 0u};
    blurX_ =
        gi::vk::Pipeline::compute(vk, shader("ssdo_blur_x.comp", ssdo_blur_x_comp, blurConstants));
    resolve_ = gi::vk::Pipeline::compute(
        vk, bounce_
                ? shader("ssdo_resolve.comp", ssdo_resolve_comp, blurConstants)
                : shader("ssdo_resolve_ambient.comp", ssdo_resolve_ambient_comp, blurConstants));
    if (layers_ > 2)
      layersPipeline_ = gi::vk::Pipeline::compute(
          vk, shader("ssdo_layers.comp", ssdo_layers_comp, {layers_}, false));
    uniforms_.create(vk);
    h_.radius = settings.handle<double>("radius");
    h_.bounce_strength = settings.handle<double>("bounce_strength");
    h_.distance_clamp = settings.handle<double>("distance_clamp");
    h_.samples = settings.handle<int>("samples");
    h_.pattern_sets = settings.handle<int>("pattern_sets");
    // The importance samples of environment_sampling=mis: two vec4 per sample slot (bound, but
    // not read, in the other modes).
    if (!environmentSamples_)
      environmentSamples_ =
          gi::vk::Buffer(vk, VkDeviceSize(kEnvironmentSlots) * 2 * sizeof(float[4]),
                         VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false);
    if (environmentSampling_ == 2)
      environmentSamplesPipeline_ = gi::vk::Pipeline::compute(
          vk, shader("ssdo_env_samples.comp", ssdo_env_samples_comp, {}, false));
  }

  // The additional cameras (seed 000 §4): displaced from the viewer by camera_displacement x
  // the scene's bounding radius (right, left, up, down in the viewer's frame), aimed at the
  // centre of interest (the point of the view axis nearest the scene's centre), the viewer's
  // projection, camera_resolution x its image.
  void update(gi::EffectContext& ctx, const gi::SettingValues& s) override {
    if (cameras_ == 0) return;
    glm::vec3 lo, hi;
    ctx.scene().bounds(lo, hi);
    const glm::vec3 centre = 0.5f * (lo + hi);
    float radius = 0.5f * glm::length(hi - lo);
    if (!std::isfinite(radius) || radius <= 0.0f) radius = 1.0f;  // guard: degenerate bounds
    const gi::CameraView& main = ctx.camera();
    const glm::mat4 inv = glm::inverse(main.view);
    const glm::vec3 eye(inv[3]), right = glm::normalize(glm::vec3(inv[0])),
                                 up = glm::normalize(glm::vec3(inv[1])),
                                 forward = -glm::normalize(glm::vec3(inv[2]));
    // Guard: a centre behind (or at) the viewer puts the centre of interest one radius ahead.
    float dist = glm::dot(centre - eye, forward);
    if (!(dist > 1e-3f * radius)) dist = radius;
    const glm::vec3 interest = eye + forward * dist;
    const float shift = float(s.number("camera_displacement")) * radius;
    const std::array<glm::vec3, 4> dirs = {right, -right, up, -up};
    const VkExtent2D e = cameraExtent(ctx, s);
    for (uint32_t c = 0; c < cameras_ && c < views_.size(); ++c) {
      gi::CameraView cam = main;
      cam.position = eye + dirs[c] * shift;
      const glm::vec3 f = interest - cam.position;
      // Guard: looking straight along the world's y, take z as the up vector.
      const glm::vec3 worldUp = std::abs(glm::dot(glm::normalize(f), glm::vec3(0, 1, 0))) > 0.999f
                                    ? glm::vec3(0, 0, 1)
                                    : glm::vec3(0, 1, 0);
      cam.view = glm::lookAt(cam.position, interest, worldUp);
      views_[c]->setCamera(cam, e);
    }
  }

  void addPasses(gi::FrameGraph& graph, gi::EffectContext& ctx,
                 const gi::SettingValues& settings) override {
    struct Io {
      gi::TextureHandle depth, gbuffer, shadowMaps;
      gi::BufferHandle lights, shadowViews;
      gi::LitSurfaceInputs litInputs;  // what ssdo_surface reads to sum the lights
      gi::TextureHandle envMap;        // the environment (its map and importance-sampling tables)
      gi::BufferHandle envSampling;
      gi::BufferHandle envSamples;  // environment_sampling=mis: ssdo_env_samples' table
      gi::TextureHandle surface, raw, half, ambient, indirect;
      // The peeled depth layers 1..layers-1 (peeled[0] is layer 1), and layers 2 and 3 packed.
      std::vector<gi::TextureHandle> peeled;
      gi::TextureHandle layers23;
      gi::TextureHandle contact;    // contact_shadow (contact_shadows)
      gi::TextureHandle direct;     // direct_light (bounce)
      gi::TextureHandle camDirect;  // the cameras' stand-in for direct_light's binding
      // Per additional camera: its depth, G-buffer (packed, motion) and surface texels.
      std::vector<gi::TextureHandle> camDepth, camSurface;
      std::vector<std::vector<gi::TextureHandle>> camG;
    };
    auto io = std::make_shared<Io>();
    gi::Blackboard& bb = graph.blackboard();
    const int blurRadius = settings.integer("blur_radius");  // changesGraph: fixed per graph
    const VkBuffer frame = ctx.frameUniforms();
    const VkSampler nearest = ctx.nearestSampler();
    gi::GpuScene& scene = ctx.scene();
    // The lights, their shadow views and maps: read by every pass that sums or tests lights.
    auto readLights = [&](gi::PassBuilder& b) {
      io->lights = b.read(bb.buffer(res::kLights));
      io->shadowViews = b.read(bb.buffer(res::kShadowViews));
      io->shadowMaps = b.read(bb.texture(res::kShadowMaps));
    };

    // Depth layer k (1..layers-1): the nearest surface strictly behind layer k-1 (layer 0: the
    // G-buffer's depth). One pass per layer: "ssdo_peel" (layer 1), "ssdo_peel2", "ssdo_peel3".
    for (uint32_t k = 1; k < layers_; ++k) {
      const std::string name = k == 1 ? "ssdo_peel" : "ssdo_peel" + std::to_string(k);
      io->peeled.emplace_back();
      graph.addPass(
          name,
          [&](gi::PassBuilder& b) {
            scene.declareRead(b);
            if (k == 1)
              io->depth = b.read(bb.texture(res::kDepth));
            else
              io->peeled[k - 2] = b.read(io->peeled[k - 2]);
            io->peeled[k - 1] = b.write(
                b.create("ssdo_layer" + std::to_string(k), gi::TextureDesc{gi::kSceneDepthFormat}),
                gi::TextureUsage::DepthAttachment);
          },
          [io, &scene, k, c = &ctx](gi::PassContext& pc) {
            gi::SceneView v;
            v.view = c->frame().view;  // exactly the G-buffer's camera
            v.proj = c->frame().proj;
            const gi::TextureHandle out = io->peeled[k - 1];
            const gi::SceneTargets t{pc.view(out), {}, pc.extent(out)};
            scene.drawDepthPeeled(pc, t, {&v, 1}, pc.view(k == 1 ? io->depth : io->peeled[k - 2]));
          });
    }

    if (cameras_ > 0) {
      const VkExtent2D ce = cameraExtent(ctx, settings);
      const uint32_t n = cameras_;
      graph.addPass(
          "ssdo_cameras",
          [&](gi::PassBuilder& b) {
            scene.declareRead(b);
            auto target = [&](const std::string& name, VkFormat f, gi::TextureUsage u) {
              return b.write(b.create(name, gi::TextureDesc{f, gi::SizeClass::Absolute, 1.0f,
                                                            ce.width, ce.height}),
                             u);
            };
            const auto formats = gi::sceneColorFormats(gi::SceneOutputs::GBuffer);
            for (uint32_t c = 0; c < n; ++c) {
              const std::string tag = "ssdo_camera" + std::to_string(c);
              io->camDepth.push_back(
                  target(tag + "_depth", gi::kSceneDepthFormat, gi::TextureUsage::DepthAttachment));
              io->camG.emplace_back();
              for (size_t i = 0; i < formats.size(); ++i)
                io->camG.back().push_back(target(tag + "_g" + std::to_string(i), formats[i],
                                                 gi::TextureUsage::ColorAttachment));
            }
          },
          [this, io, &scene, n](gi::PassContext& pc) {
            for (uint32_t c = 0; c < n; ++c) {
              gi::SceneTargets t{pc.view(io->camDepth[c]), {}, pc.extent(io->camDepth[c])};
              for (gi::TextureHandle g : io->camG[c]) t.colors.push_back(pc.view(g));
              scene.drawGBuffer(pc, t, views_[c]->buffer());
            }
          });
      // Their surface texels, as the main view's (one layer), through their own uniforms.
      graph.addPass(
          "ssdo_camera_surface",
          [&](gi::PassBuilder& b) {
            for (uint32_t c = 0; c < n; ++c) {
              io->camDepth[c] = b.read(io->camDepth[c]);
              for (gi::TextureHandle& g : io->camG[c]) g = b.read(g);
              io->camSurface.push_back(
                  b.write(b.create("ssdo_camera" + std::to_string(c) + "_surface",
                                   gi::TextureDesc{kPackedFormat, gi::SizeClass::Absolute, 1.0f,
                                                   ce.width, ce.height}),
                          gi::TextureUsage::StorageWrite));
            }
            readLights(b);
            // The cameras publish no direct light: a 1x1 image stands in for that binding.
            io->camDirect =
                b.write(b.create("ssdo_camera_direct",
                                 gi::TextureDesc{kOutFormat, gi::SizeClass::Absolute, 1.0f, 1, 1}),
                        gi::TextureUsage::StorageWrite);
          },
          [this, io, values = &settings, nearest, n, c = &ctx](gi::PassContext& pc) {
            upload(*values);
            const auto masks = lightMasks(c->lights());
            if (masks != surfaceMasks_ || pcfRadius(*c) != pcf_) buildSurface(*c, masks);
            for (uint32_t k = 0; k < n; ++k) {
              const std::vector<gi::TextureHandle>& g = io->camG[k];  // packed, motion
              const gi::LitSurfaceInputs camera{io->camDepth[k], g[0], io->shadowMaps, io->lights,
                                                io->shadowViews};
              gi::vk::DescriptorWriter w(cameraSurface_);
              w.buffer("Frame", views_[k]->buffer()).buffer("ssdo", uniforms_.handle());
              camera.bind(w, pc, nearest);
              w.image("outSurface", pc.view(io->camSurface[k]))
                  .texture("gLayer1", pc.view(io->camDepth[k]), nearest)    // unused: one layer
                  .image("outDirect", pc.view(io->camDirect))               // unused
                  .texture("gContact", pc.view(io->camDepth[k]), nearest);  // unused: no contact
              pc.dispatch(cameraSurface_, w, pc.extent(io->camSurface[k]), kGroupX, kGroupY);
            }
          });
    }

    // Contact shadows first: with the bounce ssdo_surface applies them to the direct light it
    // publishes; without it the lighting pass applies them ("contact_shadow").
    if (contact_) {
      graph.addPass(
          "ssdo_contact",
          [&](gi::PassBuilder& b) {
            io->depth = b.read(bb.texture(res::kDepth));
            io->gbuffer = b.read(bb.texture(res::kGBuffer));
            readLights(b);
            io->contact =
                b.write(b.create(res::kContactShadow, gi::TextureDesc{VK_FORMAT_R8G8B8A8_UNORM}),
                        gi::TextureUsage::StorageWrite);
          },
          [this, io, frame, nearest, c = &ctx](gi::PassContext& pc) {
            const auto masks = lightMasks(c->lights());
            if (masks != contactMasks_) buildContact(*c, masks);
            gi::vk::DescriptorWriter w(contactPipeline_);
            w.buffer("Frame", frame)
                .buffer("ssdo", uniforms_.handle())
                .texture("gDepth", pc.view(io->depth), nearest)
                .buffer("Lights", pc.buffer(io->lights))
                .buffer("ShadowViews", pc.buffer(io->shadowViews))
                .texture("shadowMaps", pc.view(io->shadowMaps), nearest)
                .image("outContact", pc.view(io->contact))
                .texture("giGBuffer", pc.view(io->gbuffer), nearest);
            pc.dispatch(contactPipeline_, w, pc.extent(io->contact), kGroupX, kGroupY);
          });
      if (!bounce_) bb.put(res::kContactShadow, io->contact);
    }

    // Directional occlusion alone reads the G-buffer depth directly (ssdo_depth.comp): no
    // surface texels.
    if (!depthInput())
      graph.addPass(
          "ssdo_surface",
          [&](gi::PassBuilder& b) {
            io->litInputs.read(b, bb);
            if (layers_ > 1) io->peeled[0] = b.read(io->peeled[0]);
            io->surface = b.write(b.create("ssdo_surface", gi::TextureDesc{kPackedFormat}),
                                  gi::TextureUsage::StorageWrite);
            if (bounce_ && contact_) io->contact = b.read(io->contact);
            // Written and published only with the bounce; without it a 1x1 image stands in for
            // the binding (a storage image of the declared format; ssdo_surface.comp writes
            // its one texel so that it holds a defined value).
            io->direct = b.write(
                bounce_
                    ? b.create(res::kDirectLight, gi::TextureDesc{kOutFormat})
                    : b.create("ssdo_direct_stand_in",
                               gi::TextureDesc{kOutFormat, gi::SizeClass::Absolute, 1.0f, 1, 1}),
                gi::TextureUsage::StorageWrite);
            if (layers_ > 2) {
              for (size_t k = 1; k < io->peeled.size(); ++k) io->peeled[k] = b.read(io->peeled[k]);
              io->layers23 = b.write(b.create("ssdo_layers23", gi::TextureDesc{kLayersFormat}),
                                     gi::TextureUsage::StorageWrite);
            }
          },
          [this, io, values = &settings, frame, nearest, c = &ctx](gi::PassContext& pc) {
            upload(*values);
            // Light types and the environment's kind can change without a graph rebuild: the
            // specialized pipelines follow (built here, before the dispatches that use them).
            const auto masks = lightMasks(c->lights());
            if (masks != surfaceMasks_ || pcfRadius(*c) != pcf_) buildSurface(*c, masks);
            const uint32_t kind = environmentKind(c->frame());
            if (kind != environmentKind_) buildSsdo(*c, kind);
            const gi::TextureHandle depth = io->litInputs.depth;
            gi::vk::DescriptorWriter w(surface_);
            w.buffer("Frame", frame).buffer("ssdo", uniforms_.handle());
            io->litInputs.bind(w, pc, nearest);
            w.image("outSurface", pc.view(io->surface))
                // The peeled layer (unused with one layer: the depth stands in).
                .texture("gLayer1", pc.view(layers_ > 1 ? io->peeled[0] : depth), nearest)
                // direct_light and the contact shadows (unused without the bounce and without
                // contact shadows: the surface and the depth stand in).
                .image("outDirect", pc.view(io->direct))
                .texture("gContact", pc.view(bounce_ && contact_ ? io->contact : depth), nearest);
            const VkExtent2D e = pc.extent(io->surface);
            pc.dispatch(surface_, w, e, kGroupX, kGroupY);
            if (layers_ > 2) {
              // Layers 2 and 3 into one R32UI texel (with 3 layers, layer 2 stands in for 3).
              gi::vk::DescriptorWriter l(layersPipeline_);
              l.buffer("Frame", frame)
                  .texture("gLayer2", pc.view(io->peeled[1]), nearest)
                  .texture("gLayer3", pc.view(io->peeled[layers_ > 3 ? 2 : 1]), nearest)
                  .image("outLayers", pc.view(io->layers23));
              pc.dispatch(layersPipeline_, l, e, kGroupX, kGroupY);
            }
          });

    if (environmentSampling_ == 2) {
      // environment_sampling=mis: the environment's importance samples, one per sample slot
      // (dispatched only while the environment is an equirect map).
      io->envSamples = graph.importBuffer("ssdo_env_samples", environmentSamples_.handle(),
                                          environmentSamples_.size());
      graph.addPass(
          "ssdo_env_samples",
          [&](gi::PassBuilder& b) {
            io->envMap = b.read(bb.texture(res::kEnvironmentMap));
            io->envSampling =
                b.read(bb.buffer(res::kEnvironmentSampling), gi::BufferUsage::StorageRead);
            io->envSamples = b.write(io->envSamples, gi::BufferUsage::StorageWrite);
          },
          [this, io, nearest, c = &ctx](gi::PassContext& pc) {
            // Only an equirect map is read per direction (the kind may change at run time
            // without a graph rebuild, as in the ssdo pass).
            if (environmentKind(c->frame()) != 2) return;
            gi::vk::DescriptorWriter w(environmentSamplesPipeline_);
            w.texture("giEnvironmentMap", pc.view(io->envMap), nearest)
                .buffer("giEnvironment", pc.buffer(io->envSampling))
                .buffer("Samples", pc.buffer(io->envSamples));
            pc.dispatch(environmentSamplesPipeline_, w, {uint32_t(kEnvironmentSlots), 1}, 64, 1);
          });
    }

    graph.addPass(
        "ssdo",
        [&](gi::PassBuilder& b) {
          if (depthInput()) {
            io->depth = b.read(bb.texture(res::kDepth));
            io->gbuffer = b.read(bb.texture(res::kGBuffer));
          } else {
            io->surface = b.read(io->surface);
          }
          for (gi::TextureHandle& t : io->camSurface) t = b.read(t);
          if (layers_ > 2) io->layers23 = b.read(io->layers23);
          io->envMap = b.read(bb.texture(res::kEnvironmentMap));
          io->envSampling =
              b.read(bb.buffer(res::kEnvironmentSampling), gi::BufferUsage::StorageRead);
          if (environmentSampling_ == 2)
            io->envSamples = b.read(io->envSamples, gi::BufferUsage::StorageRead);
          io->raw = b.write(b.create("ssdo_raw", gi::TextureDesc{kPackedFormat}),
                            gi::TextureUsage::StorageWrite);
        },
        [this, io, values = &settings, frame, nearest, c = &ctx](gi::PassContext& pc) {
          if (depthInput()) {  // what ssdo_surface's callback does otherwise
            upload(*values);
            const uint32_t kind = environmentKind(c->frame());
            if (kind != environmentKind_) buildSsdo(*c, kind);
            gi::vk::DescriptorWriter w(ssdo_);
            w.buffer("Frame", frame)
                .buffer("ssdo", uniforms_.handle())
                .image("outRaw", pc.view(io->raw))
                .texture("gDepth", pc.view(io->depth), nearest)
                .texture("giGBuffer", pc.view(io->gbuffer), nearest);
            bindEnvironment(w, pc, *io, nearest);
            pc.dispatch(ssdo_, w, pc.extent(io->raw), kGroupX, kGroupY);
            return;
          }
          uploadCameras(c->frame());
          gi::vk::DescriptorWriter w(ssdo_);
          w.buffer("Frame", frame)
              .buffer("ssdo", uniforms_.handle())
              .texture("gSurface", pc.view(io->surface), nearest)
              .image("outRaw", pc.view(io->raw));
          const char* cameraInputs[] = {"gCamera0", "gCamera1", "gCamera2", "gCamera3"};
          static_assert(std::size(cameraInputs) == gi::ssdo::kMaxCameras);
          for (uint32_t k = 0; k < gi::ssdo::kMaxCameras; ++k)
            w.texture(cameraInputs[k],
                      pc.view(k < io->camSurface.size() ? io->camSurface[k] : io->surface),
                      nearest);
          // Layers 2 and 3 (unused with up to 2 layers: the surface stands in).
          w.texture("gLayers23", pc.view(layers_ > 2 ? io->layers23 : io->surface), nearest);
          bindEnvironment(w, pc, *io, nearest);
          pc.dispatch(ssdo_, w, pc.extent(io->raw), kGroupX, kGroupY);
        });

    // Blur along x into `half`, then along y into the outputs (radius 0: no blur, pass
    // "ssdo_resolve").
    graph.addPass(
        blurRadius > 0 ? "ssdo_blur" : "ssdo_resolve",
        [&](gi::PassBuilder& b) {
          io->raw = b.read(io->raw);
          // The albedo for `indirect` (`ambient` is per unit albedo).
          if (bounce_) io->gbuffer = b.read(bb.texture(res::kGBuffer));
          if (blurRadius > 0)
            io->half = b.write(b.create("ssdo_blur_x", gi::TextureDesc{kPackedFormat}),
                               gi::TextureUsage::StorageWrite);
          io->ambient = b.write(b.create(res::kAmbient, gi::TextureDesc{kOutFormat}),
                                gi::TextureUsage::StorageWrite);
          // Without the bounce there is no indirect light to publish: the lighting pass's
          // neutral 0 stands in (and its fetch is compiled out).
          if (bounce_)
            io->indirect = b.write(b.create(res::kIndirect, gi::TextureDesc{kOutFormat}),
                                   gi::TextureUsage::StorageWrite);
        },
        [this, io, frame, nearest, blurRadius](gi::PassContext& pc) {
          const VkExtent2D e = pc.extent(io->ambient);
          VkImageView in = pc.view(io->raw);
          VkImageLayout inLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
          if (blurRadius > 0) {
            gi::vk::DescriptorWriter w(blurX_);
            w.buffer("Frame", frame)
                .buffer("ssdo", uniforms_.handle())
                .texture("inRaw", in, nearest, inLayout)
                .image("outRaw", pc.view(io->half));
            pc.dispatch(blurX_, w, e, kGroupX, kGroupY);
            // The y dispatch reads what the x dispatch wrote (the image stays GENERAL).
            gi::vk::storageWriteToSampledRead(pc.cmd(), pc.image(io->half));
            in = pc.view(io->half);
            inLayout = VK_IMAGE_LAYOUT_GENERAL;
          }
          gi::vk::DescriptorWriter w(resolve_);
          w.buffer("Frame", frame)
              .buffer("ssdo", uniforms_.handle())
              .texture("inRaw", in, nearest, inLayout)
              .image("outAmbient", pc.view(io->ambient));
          if (bounce_)
            w.texture("giGBuffer", pc.view(io->gbuffer), nearest)
                .image("outIndirect", pc.view(io->indirect));
          pc.dispatch(resolve_, w, e, kGroupX, kGroupY);
        });
    bb.put(res::kAmbient, io->ambient);
    if (bounce_) {
      bb.put(res::kIndirect, io->indirect);
      bb.put(res::kDirectLight, io->direct);
    }
  }

 private:
  // Directional occlusion alone (no bounce, one layer, no cameras): the taps need only depth.
  bool depthInput() const { return !bounce_ && layers_ == 1 && cameras_ == 0; }

  // The environment map, its importance-sampling tables and the MIS samples (ssdo.glsl).
  template <class Io>
  void bindEnvironment(gi::vk::DescriptorWriter& w, gi::PassContext& pc, const Io& io,
                       VkSampler sampler) const {
    w.texture("giEnvironmentMap", pc.view(io.envMap), sampler)
        .buffer("giEnvironment", pc.buffer(io.envSampling))
        .buffer("EnvironmentSamples", environmentSampling_ == 2 ? pc.buffer(io.envSamples)
                                                                : environmentSamples_.handle());
  }

  static uint32_t environmentKind(const gi::FrameUniforms& f) {
    return uint32_t(std::clamp(int(std::lround(f.skyHorizon.w)), 0, 2));
  }

  void buildSsdo(gi::EffectContext& ctx, uint32_t kind) {
    const std::vector<uint32_t> constants = {samples_, bounce_ ? 1u : 0u, kind,
                                             layers_,  cameras_,          environmentSampling_};
    ssdo_ = gi::vk::Pipeline::compute(
        ctx.vulkan(), depthInput() ? shader("ssdo_depth.comp", ssdo_depth_comp, constants)
                                   : shader("ssdo.comp", ssdo_comp, constants));
    environmentKind_ = kind;
  }

  // The contact-shadow pipeline, specialized to the sample count and the light types present.
  void buildContact(gi::EffectContext& ctx, std::array<uint32_t, 2> masks) {
    contactPipeline_ = gi::vk::Pipeline::compute(
        ctx.vulkan(),
        shader("ssdo_contact.comp", ssdo_contact_comp, {contactSamples_, masks[0], masks[1]}));
    contactMasks_ = masks;
  }

  // The engine's PCF radius (frame options), as the lighting pass's specialization.
  static uint32_t pcfRadius(gi::EffectContext& ctx) {
    return uint32_t(std::clamp(int(ctx.frame().options.x), 0, 3));
  }

  // The surface pipelines of the main view (with its layers; with the bounce it sums the lights
  // as the lighting pass does, PCF and contact shadows included, and publishes them) and of the
  // additional cameras (one layer; their senders' lights with a 1-tap shadow test), specialized
  // to the light types present.
  void buildSurface(gi::EffectContext& ctx, std::array<uint32_t, 2> masks) {
    pcf_ = pcfRadius(ctx);
    auto build = [&](uint32_t layers, bool mainView) {
      const bool direct = mainView && bounce_;
      return gi::vk::Pipeline::compute(
          ctx.vulkan(), shader("ssdo_surface.comp", ssdo_surface_comp,
                               {bounce_ ? 1u : 0u, masks[0], masks[1], layers, mainView ? pcf_ : 0u,
                                direct ? 1u : 0u, direct && contact_ ? 1u : 0u}));
    };
    surface_ = build(layers_, true);
    if (cameras_ > 0) cameraSurface_ = build(1, false);
    surfaceMasks_ = masks;
  }

  VkExtent2D cameraExtent(gi::EffectContext& ctx, const gi::SettingValues& s) const {
    const VkExtent2D e = ctx.outputExtent();
    const double k = std::clamp(s.number("camera_resolution"), 0.125, 1.0);
    return {std::max(1u, uint32_t(std::lround(e.width * k))),
            std::max(1u, uint32_t(std::lround(e.height * k)))};
  }

  // The additional cameras' transforms and projections of this frame, into the uniforms.
  void uploadCameras(const gi::FrameUniforms& main) {
    if (cameras_ == 0) return;
    std::array<gi::ssdo::Camera, gi::ssdo::kMaxCameras> cams{};
    for (uint32_t c = 0; c < cameras_ && c < views_.size(); ++c) {
      const gi::FrameUniforms& v = views_[c]->current();
      const glm::mat4 to = v.view * main.invView, from = glm::inverse(to);
      std::memcpy(cams[c].toCamera, glm::value_ptr(to), sizeof cams[c].toCamera);
      std::memcpy(cams[c].fromCamera, glm::value_ptr(from), sizeof cams[c].fromCamera);
      const float p[4] = {v.proj[0][0], v.proj[1][1], v.proj[2][0], v.proj[2][1]};
      std::memcpy(cams[c].proj, p, sizeof p);
      const float sz[4] = {v.viewport.x, v.viewport.y, v.viewport.z, v.viewport.w};
      std::memcpy(cams[c].size, sz, sizeof sz);
    }
    uniforms_.writePart(cams.data(), sizeof cams, offsetof(gi::ssdo::Uniforms, cameras));
  }

  // Host-visible, written while recording: the renderer waits for each frame before it records
  // the next. Rebuilt only when a setting changed since the last upload.
  void upload(const gi::SettingValues& s) {
    const std::array<double, 5> key = {s[h_.radius], double(s[h_.samples]),
                                       double(s[h_.pattern_sets]), s[h_.bounce_strength],
                                       s[h_.distance_clamp]};
    uniforms_.update(key, [&] {
      return gi::ssdo::makeUniforms(key[0], int(key[1]), int(key[2]), key[3], key[4]);
    });
  }

  gi::vk::Pipeline surface_, cameraSurface_, ssdo_, blurX_, resolve_, contactPipeline_,
      layersPipeline_;
  gi::UniformBlock<gi::ssdo::Uniforms> uniforms_;  // cameras: written every frame (writePart)
  struct Handles {  // typed settings read every frame, found by name in prepare()
    gi::Setting<double> radius, bounce_strength, distance_clamp;
    gi::Setting<int> samples, pattern_sets;
  } h_;
  std::vector<std::shared_ptr<gi::ViewUniforms>> views_;  // the additional cameras
  bool bounce_ = true;
  uint32_t samples_ = 12, environmentKind_ = 0, layers_ = 1, cameras_ = 0, pcf_ = 1;
  uint32_t environmentSampling_ = 0;  // 0 SH9, 1 map, 2 map with MIS (ssdo.glsl)
  // Sample slots (gi::ssdo::kPhases x kMaxSamples; ssdo_env.glsl's kEnvironmentSlots).
  static constexpr int kEnvironmentSlots = gi::ssdo::kPhases * gi::ssdo::kMaxSamples;
  gi::vk::Buffer environmentSamples_;
  gi::vk::Pipeline environmentSamplesPipeline_;
  std::array<uint32_t, 2> surfaceMasks_{7, 7};
  bool contact_ = false;
  uint32_t contactSamples_ = 4;
  std::optional<std::array<uint32_t, 2>> contactMasks_;  // built on first use
};

}  // namespace

GI_EFFECT_MODULE(SsdoEffect)
