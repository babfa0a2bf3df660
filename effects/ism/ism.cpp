// Instant radiosity with imperfect shadow maps (Ritschel, Grosch, Kim, Seidel, Dachsbacher,
// Kautz 2008; seed 002; README.md). Passes: a reflective shadow map of the primary light
// (ism_rsm), VPLs by importance sampling its flux (ism_vpl), per VPL a paraboloid imperfect
// shadow map splatted from a subset of the surface points (ism_splat) and hole-filled by
// pull-push (ism_pull_push) -- or, in `classic` mode, accurate paraboloid shadow maps drawn from
// the triangles (ism_classic_sm) --, interleaved gathering (ism_gather) and a geometry-aware blur
// (ism_blur) into "indirect", which the lighting pass adds.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <memory>
#include <vector>

#include "gi/effect.h"
#include "gi/effect_registry.h"
#include "gi/effect_shader.h"
#include "gi/errors.h"
#include "gi/lights.h"
#include "gi/vk/pipeline.h"
#include "gi/vk/resources.h"
#include "ism_atlas_view.comp.h"
#include "ism_blur_x.comp.h"
#include "ism_blur_y.comp.h"
#include "ism_blur_y_low.comp.h"
#include "ism_bounce.comp.h"
#include "ism_classic_atlas_view.comp.h"
#include "ism_classic_views.comp.h"
#include "ism_env_vpl.comp.h"
#include "ism_gather.comp.h"
#include "ism_gather_classic.comp.h"
#include "ism_irsm.comp.h"
#include "ism_irsm_classic.comp.h"
#include "ism_params.h"
#include "ism_pull_push.comp.h"
#include "ism_splat.comp.h"
#include "ism_upsample.comp.h"
#include "ism_vpl.comp.h"

namespace {

namespace res = gi::resources;
using gi::SettingType;

constexpr VkFormat kRawFormat = VK_FORMAT_R32G32B32A32_UINT;
constexpr VkFormat kAtlasFormat = VK_FORMAT_R32_UINT;
constexpr VkFormat kOutFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr uint32_t kGroupX = 32, kGroupY = 16;

// A pipeline of one of the ISM shaders; those that read ism_common.glsl's IsmParams check it
// against gi::ism::Uniforms, and `Push` (when given) against the shader's push constants.
template <size_t N>
gi::vk::ComputeDesc shader(const char* name, const uint32_t (&words)[N],
                           std::vector<uint32_t> constants = {}, bool readsParams = true) {
  using gi::ism::Uniforms;
  gi::vk::ComputeDesc d =
      gi::computeShader(std::string("ism: ") + name, words, std::move(constants));
  if (readsParams)
    d.blocks.uniforms = {{"ism", GI_CPP_BLOCK(Uniforms, rsm, atlas, bias, pull, gather, blur,
                                              envSphere, envVpls, nearField, envDepth)}};
  return d;
}

// The push constants of ism_splat.comp, ism_pull_push.comp, ism_classic_views.comp,
// ism_irsm.glsl and ism_bounce.comp.
struct SplatPush {
  int32_t base, firstTile;
};
struct PullPushPush {
  int32_t tileBegin, tileEnd, firstBlockRow;
};
struct ClassicViewsPush {
  int32_t first, count, firstTile;
};
struct IrsmPush {
  int32_t base;
};
struct BouncePush {
  int32_t bounce;
};
// Debug view of the shadow-map atlas (distances, R32F); its pass runs only when it is viewed.
constexpr const char* kAtlasView = "ism_atlas";
constexpr VkDeviceSize kVplBytes = 3 * sizeof(glm::vec4);

int floorPow2(int v) {
  int p = 1;
  while (p * 2 <= v) p *= 2;
  return p;
}
int log2i(int v) {
  int l = 0;
  while ((1 << (l + 1)) <= v) ++l;
  return l;
}

// The graph-fixed configuration, derived once per prepare().
struct Config {
  int vpls = 256, padded = 256, block = 4, perPixel = 16, res = 64, perRow = 16, rows = 16;
  int perIsm = 1024, levels = 2, rsm = 64, splat = 1, blurExtra = 0, bounces = 1, scale = 1;
  int total() const { return vpls * bounces; }  // VPLs of all bounces (one tile each)
  // Environment VPLs (ism_env_vpl.comp): count, padded to whole k x k blocks, per pixel; their
  // tiles follow the point VPLs' in the atlas.
  int env = 0, envPadded = 0, envPerPixel = 0;
  int tiles() const { return total() + envPadded; }
  bool classic = false;
  bool glossy = false;  // Phong receivers (ism_glossy.glsl)
  float phong = 0.0f;   // Phong exponent, 0: from the roughness
  uint32_t atlasWidth() const { return uint32_t(perRow * res); }
  uint32_t atlasHeight() const { return uint32_t(rows * res); }
};

class IsmEffect : public gi::Effect {
 public:
  // "ambient" is published (as "nothing") only with environment VPLs, which then carry the
  // environment's light in "indirect", shadowed, in place of the engine's unshadowed term.
  gi::EffectInfo info() const override {
    return {
        .name = "ism",
        .version = "1.0",
        .description =
            "instant radiosity with imperfect shadow maps (Ritschel et al. 2008): VPLs from the "
            "primary light's RSM, point-splatted paraboloid ISMs with pull-push, interleaved "
            "gathering, geometry-aware blur; 1 to 3 diffuse bounces; optionally the "
            "environment as directional VPLs with orthographic ISMs",
        .stage = gi::EffectStage::BeforeLighting,
        .reads = {res::kDepth, res::kGBuffer, res::kSurfacePoints, res::kEnvironmentMap,
                  res::kEnvironmentSampling, res::kAO, res::kIndirect},
        .writes = {res::kIndirect, res::kAmbient, kAtlasView},
        .debugView = res::kIndirect,
        .estimates = gi::GroundTruth::IndirectLight};
  }

  std::vector<gi::SettingDesc> settings() const override {
    using gi::ism::kMaxVpls;
    return {
        gi::SettingDesc::samples(
            "vpls", 256, 1, kMaxVpls,
            "virtual point lights N_vpl per bounce, the first sampled from the primary light's RSM "
            "(each gets one ISM)",
            true),
        {"ism_resolution", SettingType::Int, 64, 8, gi::ism::kMaxIsmResolution,
         "side of each VPL's paraboloid shadow map in texels (rounded down to a power of two)",
         true},
        {"points_per_ism", SettingType::Int, 1024, 16, 65536,
         "surface points splatted into each ISM (a fixed subset per VPL; the engine keeps "
         "min(vpls x points_per_ism, 2^21) points)",
         true},
        {"pull_push_levels", SettingType::Int, 1, 0, gi::ism::kMaxPullPushLevels,
         "pull-push pyramid levels filling the ISMs' holes (0: none; at most log2 resolution)",
         true},
        {"pull_threshold", SettingType::Float, 0.05, 0.0, 1.0,
         "pull outlier threshold, fraction of the scene extent at level 0 (x 2^level): "
         "children farther than this behind the nearest are not averaged",
         false},
        // Default 1 (no distance in the scene is that far behind): holes only. Replacing
        // texels behind the near surface, even where it holds most of the block, darkened
        // every benchmark scene against classic maps (demo.json at `high`: image NRMSE 0.088
        // vs 0.042 with holes only); the splats sized by each point's share of the area close
        // the leaks it was for.
        {"push_threshold", SettingType::Float, 1.0, 0.0, 1.0,
         "push outlier threshold, fraction of the scene extent at level 0 (x 2^level): a "
         "texel this far behind a coarse value standing for most of its block is replaced by "
         "it (1: only holes are filled)",
         false},
        {"block_size", SettingType::Int, 4, 1, gi::ism::kMaxBlock,
         "interleaving block k: each pixel of a k x k block gathers N_vpl / k^2 VPLs", true},
        {"bounces", SettingType::Int, 1, 1, gi::ism::kMaxBounces,
         "indirect bounces: each bounce after the first samples `vpls` more VPLs from the "
         "previous bounce's imperfect reflective shadow maps (its VPLs' point subsets shaded "
         "where their maps see them), each with its own map; vpls x bounces is capped at 1024",
         true},
        gi::SettingDesc::enumeration("mode", {"ism", "classic"}, 0,
                                     "ism: imperfect shadow maps from points; classic: accurate "
                                     "paraboloid shadow maps from the triangles (reference)",
                                     true),
        {"rsm_resolution", SettingType::Int, 64, 16, 256,
         "side of the reflective shadow map's face (a point light gets six cube faces in a 3 x 2 "
         "atlas; a spot light one perspective face, or a paraboloid beyond 60 degrees)",
         true},
        {"bias", SettingType::Float, 0.01, 0.0, 1.0,
         "constant shadow bias, fraction of the scene extent", false},
        {"bias_slope", SettingType::Float, 0.1, 0.0, 4.0,
         "shadow bias per unit distance to the VPL (grows with the texel footprint)", false},
        {"distance_clamp", SettingType::Float, gi::ism::kDistanceClamp, 1e-6, 1.0,
         "VPL singularity guard d_min as a fraction of the scene extent: 1 / max(d^2, d_min^2)",
         false},
        {"splat_radius", SettingType::Int, 1, 0, gi::ism::kMaxSplatRadius,
         "largest splat radius in texels (the radius follows the area each point stands for "
         "in its map, its share x the points per map's fraction of all, / distance^2)",
         true},
        {"splat_scale", SettingType::Float, 1.0, 0.0, 8.0,
         "scales the splat radius computed from the point's footprint", false},
        {"gather_scale", SettingType::Int, 1, 1, 4,
         "gather and blur at 1 / gather_scale of the resolution (each pixel stands for the "
         "G-buffer pixel at its scaled position), then a geometry-aware bilinear upsample",
         true},
        {"blur_radius", SettingType::Int, 0, 0, 8,
         "blur taps beyond the k that cancel the block pattern, each side", true},
        {"blur_tolerance", SettingType::Float, 0.05, 0.0, 1.0,
         "blur: distance a neighbour may lie from the centre's tangent plane, relative to the view "
         "distance",
         false},
        {"strength", SettingType::Float, 1.0, 0.0, 16.0, "scales the indirect light", false},
        {"glossy", SettingType::Bool, 0.0, 0.0, 1.0,
         "receivers also reflect the VPLs' light with a Phong lobe (f0 x (n + 2) / (2 pi) "
         "cos^n, f0 as the lighting pass: 0.04, or the albedo of metals); off: diffuse only",
         true},
        {"phong_exponent", SettingType::Float, 0.0, 0.0, gi::ism::kMaxPhongExponent,
         "glossy receivers' Phong exponent n (0: from each pixel's roughness, the lighting "
         "pass's Blinn-Phong exponent / 4, within [1, 128])",
         true},
        {"environment_vpls", SettingType::Int, 0, 0, gi::ism::kMaxEnvVpls,
         "directional VPLs importance-sampled from the environment map, each with an "
         "orthographic ISM (seed 002 §5): the environment's light, shadowed, replaces the "
         "engine's unshadowed environment term (0: off; classic mode: orthographic maps "
         "drawn from the triangles)",
         true},
        {"environment_normal_offset", SettingType::Float, 2.0, 0.0, 8.0,
         "environment VPLs: receivers look up their orthographic maps from this many texels "
         "along their normal (with the constant `bias`; see ism_lookup.glsl)",
         false},
        {"environment_fit_view", SettingType::Bool, 1, 0, 1,
         "environment VPLs: their orthographic maps cover the scene within the camera's frustum "
         "(smaller texels where the view holds part of the scene; occluders outside still "
         "count) instead of the scene's whole bounding sphere",
         false},
    };
  }

  void prepare(gi::EffectContext& ctx, const gi::SettingValues& s) override {
    h_.distance_clamp = s.handle<double>("distance_clamp");
    h_.bias = s.handle<double>("bias");
    h_.bias_slope = s.handle<double>("bias_slope");
    h_.pull_threshold = s.handle<double>("pull_threshold");
    h_.push_threshold = s.handle<double>("push_threshold");
    h_.strength = s.handle<double>("strength");
    h_.blur_tolerance = s.handle<double>("blur_tolerance");
    h_.splat_scale = s.handle<double>("splat_scale");
    h_.environment_normal_offset = s.handle<double>("environment_normal_offset");
    h_.environment_fit_view = s.handle<bool>("environment_fit_view");
    gi::vk::Context& vk = ctx.vulkan();
    vk.requireWorkgroup(kGroupX, kGroupY, "ism");
    Config c;
    c.bounces = std::clamp(s.integer("bounces"), 1, gi::ism::kMaxBounces);
    // The VPL table holds every bounce's VPLs: at most kMaxVpls in all.
    c.vpls = std::clamp(s.integer("vpls"), 1, gi::ism::kMaxVpls / c.bounces);
    c.block = std::clamp(s.integer("block_size"), 1, gi::ism::kMaxBlock);
    const int k2 = c.block * c.block;
    c.perPixel = (c.total() + k2 - 1) / k2;
    c.padded = c.perPixel * k2;
    c.classic = s.option("mode") == "classic";
    c.env = std::clamp(s.integer("environment_vpls"), 0, gi::ism::kMaxEnvVpls);
    c.envPerPixel = (c.env + k2 - 1) / k2;
    c.envPadded = c.envPerPixel * k2;
    c.res = floorPow2(std::clamp(s.integer("ism_resolution"), 8, gi::ism::kMaxIsmResolution));
    c.perRow = int(std::ceil(std::sqrt(double(c.tiles()))));
    c.rows = (c.tiles() + c.perRow - 1) / c.perRow;
    c.perIsm = s.integer("points_per_ism");
    c.levels = std::clamp(s.integer("pull_push_levels"), 0, log2i(c.res));
    c.rsm = s.integer("rsm_resolution");
    c.splat = s.integer("splat_radius");
    c.blurExtra = s.integer("blur_radius");
    c.scale = std::clamp(s.integer("gather_scale"), 1, 4);
    c.glossy = s.flag("glossy");
    c.phong = float(s.number("phong_exponent"));
    cfg_ = c;
    nearest_ = ctx.nearestSampler();
    // The engine keeps at least the points asked for: without the cap every subset fits.
    const bool wrap = uint64_t(c.tiles()) * uint64_t(c.perIsm) > gi::ism::kMaxPoints;
    // Classic mode needs points only for the later bounces' IRSMs (the same subsets).
    if (!c.classic || c.bounces > 1)
      ctx.requestSurfacePoints(uint32_t(
          std::min<uint64_t>(uint64_t(c.tiles()) * uint64_t(c.perIsm), gi::ism::kMaxPoints)));

    using gi::vk::cppBlock;
    auto make = [&](gi::vk::ComputeDesc d, std::optional<gi::vk::CppBlock> push = {}) {
      d.blocks.pushConstants = std::move(push);
      return gi::vk::Pipeline::compute(vk, d);
    };
    const auto splatPush = GI_CPP_BLOCK(SplatPush, base, firstTile);
    const auto irsmPush = GI_CPP_BLOCK(IrsmPush, base);
    vpl_ = make(shader("ism_vpl.comp", ism_vpl_comp));
    if (c.classic) {
      auto views = [&](bool ortho) {
        return make(shader("ism_classic_views.comp", ism_classic_views_comp, {uint32_t(ortho)}),
                    GI_CPP_BLOCK(ClassicViewsPush, first, count, firstTile));
      };
      classicViews_ = views(false);
      if (c.env > 0) envClassicViews_ = views(true);
    }
    if (!c.classic) {
      splat_ = make(
          shader("ism_splat.comp", ism_splat_comp, {uint32_t(c.splat), uint32_t(wrap ? 1 : 0), 0u}),
          splatPush);
      if (c.env > 0)
        envSplat_ = make(shader("ism_splat.comp", ism_splat_comp,
                                {uint32_t(c.splat), uint32_t(wrap ? 1 : 0), 1u}),
                         splatPush);
      if (c.levels > 0)
        pullPush_ = make(shader("ism_pull_push.comp", ism_pull_push_comp, {uint32_t(c.levels)}),
                         GI_CPP_BLOCK(PullPushPush, tileBegin, tileEnd, firstBlockRow));
    }
    if (c.env > 0) envVpl_ = make(shader("ism_env_vpl.comp", ism_env_vpl_comp));
    if (c.bounces > 1) {
      const uint32_t entries = gi::ism::irsmEntries(c.perIsm), wraps = wrap ? 1 : 0;
      irsm_ = c.classic
                  ? make(shader("ism_irsm_classic.comp", ism_irsm_classic_comp, {entries, wraps}),
                         irsmPush)
                  : make(shader("ism_irsm.comp", ism_irsm_comp, {entries, wraps}), irsmPush);
      bounce_ = make(shader("ism_bounce.comp", ism_bounce_comp, {uint32_t(c.vpls), entries, wraps}),
                     GI_CPP_BLOCK(BouncePush, bounce));
    }
    atlasView_ =
        c.classic
            ? make(shader("ism_classic_atlas_view.comp", ism_classic_atlas_view_comp, {}, false))
            : make(shader("ism_atlas_view.comp", ism_atlas_view_comp, {}, false));
    const std::vector<uint32_t> gatherSpec = {uint32_t(c.perPixel),
                                              uint32_t(c.block),
                                              uint32_t(c.scale),
                                              uint32_t(c.glossy),
                                              glm::floatBitsToUint(c.phong),
                                              uint32_t(c.envPerPixel)};
    gather_ = c.classic
                  ? make(shader("ism_gather_classic.comp", ism_gather_classic_comp, gatherSpec))
                  : make(shader("ism_gather.comp", ism_gather_comp, gatherSpec));
    // K taps from -K/2 cover each phase of a K-periodic pattern exactly once.
    const int lo = -c.block / 2 - c.blurExtra, hi = c.block - 1 - c.block / 2 + c.blurExtra;
    const std::vector<uint32_t> blurSpec = {uint32_t(lo), uint32_t(hi), uint32_t(c.scale),
                                            uint32_t(c.glossy)};
    blurX_ = make(shader("ism_blur_x.comp", ism_blur_x_comp, blurSpec));
    if (c.scale == 1) {
      blurY_ = make(shader("ism_blur_y.comp", ism_blur_y_comp, blurSpec));
    } else {
      blurY_ = make(shader("ism_blur_y_low.comp", ism_blur_y_low_comp, blurSpec));
      upsample_ = make(
          shader("ism_upsample.comp", ism_upsample_comp, {uint32_t(c.scale), uint32_t(c.glossy)}));
    }
    if (!uniforms_)
      uniforms_ =
          gi::vk::Buffer(vk, sizeof(gi::ism::Uniforms), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, true);
    // VPL tables, host-visible: zero-filled once from the host (slots no VPL pass wrote read
    // as no light). The environment VPLs' is bound to the gathering also when there are none.
    for (gi::vk::Buffer* table : {&vplBuffer_, &envBuffer_}) {
      if (*table) continue;
      *table = gi::vk::Buffer(
          vk, kVplBytes * gi::ism::kVplSlots,
          VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true);
      std::fill_n(static_cast<char*>(table->mapped()), table->size(), 0);
    }
  }

  void addPasses(gi::FrameGraph& graph, gi::EffectContext& ctx,
                 const gi::SettingValues& settings) override {
    struct Io {
      gi::TextureHandle rsmDepth, rsmPos, rsmNormal, rsmFlux, atlas, depth, gbuffer, raw, half, low,
          indirect, atlasView;
      gi::BufferHandle cdf, vpls, points, envVpls, envSampling;
      gi::TextureHandle envMap, ambient, ao, prior;
    };
    const Config c = cfg_;
    // Near/far split with effects that ran before (nothing counted twice): an AO's occluders
    // within its range are left to its "ao"; an earlier "indirect" (e.g. SSDO's near-field
    // bounce) has the first bounce's light from senders within its range, the gathering skips
    // those VPLs and adds the rest to it.
    gi::Blackboard& bb = graph.blackboard();
    aoRange_ = c.env > 0 && bb.has(res::kAO) ? float(ctx.publishedRange(res::kAO)) : 0.0f;
    indirectRange_ = bb.has(res::kIndirect) ? float(ctx.publishedRange(res::kIndirect)) : 0.0f;
    // No light to bounce and no sky to carry: no pass at all (the renderer names the effect
    // in a warning) rather than a frame of passes that add exactly nothing.
    const auto& lights = ctx.lights();
    if (c.env == 0 && (lights.empty() || glm::dot(lights.front().radiance, glm::vec3(1)) <= 0.0f))
      return;
    auto io = std::make_shared<Io>();
    const VkBuffer frame = ctx.frameUniforms();
    const VkSampler nearest = ctx.nearestSampler(), linear = ctx.linearSampler();
    const VkBuffer params = uniforms_.handle();
    // The gathering's resolution (gather_scale): the raw and blurred textures.
    const gi::TextureDesc rawDesc{kRawFormat, gi::SizeClass::OutputRelative, 1.0f / float(c.scale)};
    auto absolute = [](VkFormat f, uint32_t w, uint32_t h, uint32_t mips = 1) {
      gi::TextureDesc d{f, gi::SizeClass::Absolute, 1.0f, w, h};
      d.mips = mips;
      return d;
    };

    // 1. Reflective shadow map of the primary light (drawRsm below: cube faces, one face or an
    // orthographic view).
    graph.addPass(
        "ism_rsm",
        [&](gi::PassBuilder& b) {
          ctx.scene().declareRead(b);
          const uint32_t w = uint32_t(3 * c.rsm), h = uint32_t(2 * c.rsm);
          const std::vector<VkFormat> f =
              gi::sceneColorFormats(gi::SceneOutputs::ReflectiveShadowMap);
          io->rsmDepth = b.write(b.create("ism_rsm_depth", absolute(gi::kSceneDepthFormat, w, h)),
                                 gi::TextureUsage::DepthAttachment);
          io->rsmPos = b.write(b.create("ism_rsm_position", absolute(f[0], w, h)),
                               gi::TextureUsage::ColorAttachment);
          io->rsmNormal = b.write(b.create("ism_rsm_normal", absolute(f[1], w, h)),
                                  gi::TextureUsage::ColorAttachment);
          io->rsmFlux = b.write(b.create("ism_rsm_flux", absolute(f[2], w, h)),
                                gi::TextureUsage::ColorAttachment);
        },
        [this, io, c, values = &settings, cx = &ctx](gi::PassContext& pc) {
          upload(*cx, *values);
          drawRsm(pc, *cx, *io, c);
        });

    // 2. VPLs from the RSM's flux.
    io->vpls = graph.importBuffer("ism_vpls", vplBuffer_.handle(), vplBuffer_.size());
    graph.addPass(
        "ism_vpl",
        [&](gi::PassBuilder& b) {
          io->rsmPos = b.read(io->rsmPos);
          io->rsmNormal = b.read(io->rsmNormal);
          io->rsmFlux = b.read(io->rsmFlux);
          io->cdf = b.write(
              b.create("ism_cdf", gi::BufferDesc{VkDeviceSize(6 * c.rsm * c.rsm) * sizeof(float)}),
              gi::BufferUsage::StorageWrite);
          io->vpls = b.write(io->vpls, gi::BufferUsage::StorageWrite);
        },
        [this, io, frame, nearest, params](gi::PassContext& pc) {
          gi::vk::DescriptorWriter w(vpl_);
          w.buffer("Frame", frame)
              .buffer("ism", params)
              .texture("rsmPosition", pc.view(io->rsmPos), nearest)
              .texture("rsmNormal", pc.view(io->rsmNormal), nearest)
              .texture("rsmFlux", pc.view(io->rsmFlux), nearest)
              .buffer("Cdf", pc.buffer(io->cdf))
              .buffer("Vpls", pc.buffer(io->vpls));
          pc.dispatch(vpl_, w, {1, 1}, 1, 1);
        });

    // 3. One shadow map per VPL in an atlas: imperfect (points + pull-push) or classic; and the
    // next bounces' VPLs from points lit by the previous bounce (their maps follow).
    if (!c.classic) {
      // Cleared by a transfer (llvmpipe fills memory far faster than a compute pass stores
      // texels); one clear for every bounce's tiles: the later splats only add points.
      graph.addPass(
          "ism_clear",
          [&](gi::PassBuilder& b) {
            io->atlas = b.write(
                b.create("ism_atlas", absolute(kAtlasFormat, c.atlasWidth(), c.atlasHeight())),
                gi::TextureUsage::TransferDst);
          },
          [io](gi::PassContext& pc) {
            const VkClearColorValue empty{.uint32 = {gi::ism::kEmpty, 0u, 0u, 0u}};
            const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
            vkCmdClearColorImage(pc.cmd(), pc.image(io->atlas),
                                 VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &empty, 1, &range);
          });
      graph.addPass(
          "ism_splat",
          [&](gi::PassBuilder& b) {
            io->vpls = b.read(io->vpls, gi::BufferUsage::Uniform);
            io->points = b.read(bb.buffer(res::kSurfacePoints), gi::BufferUsage::StorageRead);
            io->atlas = b.read(io->atlas, gi::TextureUsage::StorageRead);
            io->atlas = b.write(io->atlas, gi::TextureUsage::StorageWrite);
          },
          [this, io, c](gi::PassContext& pc) {
            uploadPointCount(pc, io->points);
            splat(pc, *io, c, 0);
          });
      addPullPush(graph, io, c, 0, c.vpls, "ism_pull_push");
      for (int bounce = 1; bounce < c.bounces; ++bounce) {
        addBounce(graph, ctx, io, bounce);
        const std::string n = std::to_string(bounce + 1);
        graph.addPass(
            "ism_splat" + n,
            [&](gi::PassBuilder& b) {
              io->vpls = b.read(io->vpls, gi::BufferUsage::Uniform);
              io->points = b.read(io->points, gi::BufferUsage::StorageRead);
              io->atlas =
                  b.read(io->atlas, gi::TextureUsage::StorageRead, gi::Subresource::mipLevel(0));
              io->atlas =
                  b.write(io->atlas, gi::TextureUsage::StorageWrite, gi::Subresource::mipLevel(0));
            },
            [this, io, c, bounce](gi::PassContext& pc) { splat(pc, *io, c, bounce); });
        addPullPush(graph, io, c, bounce * c.vpls, (bounce + 1) * c.vpls, "ism_pull_push" + n);
      }
      if (c.env > 0) addEnvironmentVpls(graph, ctx, io);
    } else {
      addClassicMaps(graph, ctx, io,
                     absolute(gi::kSceneDepthFormat, c.atlasWidth(), c.atlasHeight()),
                     bounceRange(0));
      if (c.bounces > 1) io->points = graph.blackboard().buffer(res::kSurfacePoints);
      for (int bounce = 1; bounce < c.bounces; ++bounce) {
        addBounce(graph, ctx, io, bounce);
        addClassicMaps(graph, ctx, io, {}, bounceRange(bounce));
      }
      if (c.env > 0) addEnvironmentVpls(graph, ctx, io);
    }

    // The atlas as a debug view (culled unless viewed).
    graph.addPass(
        "ism_atlas_view",
        [&](gi::PassBuilder& b) {
          io->atlas = b.read(io->atlas, gi::TextureUsage::Sampled, gi::Subresource::mipLevel(0));
          io->atlasView = b.write(
              b.create(kAtlasView, absolute(VK_FORMAT_R32_SFLOAT, c.atlasWidth(), c.atlasHeight())),
              gi::TextureUsage::StorageWrite);
        },
        [this, io, nearest](gi::PassContext& pc) {
          gi::vk::DescriptorWriter w(atlasView_);
          w.texture("atlas", pc.view(io->atlas, gi::Subresource::mipLevel(0)), nearest)
              .image("view", pc.view(io->atlasView));
          pc.dispatch(atlasView_, w, pc.extent(io->atlasView), kGroupX, kGroupY);
        });
    bb.put(kAtlasView, io->atlasView);

    // 4. Interleaved gathering.
    graph.addPass(
        "ism_gather",
        [&](gi::PassBuilder& b) {
          io->depth = b.read(bb.texture(res::kDepth));
          io->gbuffer = b.read(bb.texture(res::kGBuffer));
          io->vpls = b.read(io->vpls, gi::BufferUsage::Uniform);
          io->atlas = b.read(io->atlas, gi::TextureUsage::Sampled, gi::Subresource::mipLevel(0));
          if (c.env > 0) {
            io->envVpls = b.read(io->envVpls, gi::BufferUsage::Uniform);
            // An AO effect's "ao" darkens the environment VPLs' light for the occluders within
            // its range; their maps count only those beyond it (near/far split, nothing twice).
            io->ao = b.readOptional(res::kAO);
          }
          io->raw = b.write(b.create("ism_raw", rawDesc), gi::TextureUsage::StorageWrite);
        },
        [this, io, c, frame, nearest, linear, params](gi::PassContext& pc) {
          gi::vk::DescriptorWriter w(gather_);
          w.buffer("Frame", frame)
              .buffer("ism", params)
              .buffer("Vpls", pc.buffer(io->vpls))
              .texture("gDepth", pc.view(io->depth), nearest)
              .texture("giGBuffer", pc.view(io->gbuffer), nearest)
              .texture("maps", pc.view(io->atlas, gi::Subresource::mipLevel(0)), nearest)
              .image("outRaw", pc.view(io->raw))
              .buffer("EnvVpls", c.env > 0 ? pc.buffer(io->envVpls) : envBuffer_.handle())
              // Without environment VPLs the shader never samples it (ENV_PER_PIXEL = 0).
              .texture("aoTexture", pc.view(c.env > 0 ? io->ao : io->depth),
                       c.env > 0 ? linear : nearest);
          pc.descriptors().bind(pc.cmd(), gather_, w);
          const VkExtent2D e = pc.extent(io->raw);
          const uint32_t k = uint32_t(c.block);
          const uint32_t sx = (e.width + k - 1) / k, sy = (e.height + k - 1) / k;
          vkCmdDispatch(pc.cmd(), (sx + kGroupX - 1) / kGroupX, (sy + kGroupY - 1) / kGroupY,
                        k * k);
        });

    // 5. Geometry-aware blur (x, then y with the diffuse albedo) into "indirect".
    graph.addPass(
        "ism_blur",
        [&](gi::PassBuilder& b) {
          io->raw = b.read(io->raw);
          io->gbuffer = b.read(bb.texture(res::kGBuffer));
          io->half = b.write(b.create("ism_blur_x", rawDesc), gi::TextureUsage::StorageWrite);
          if (c.scale > 1) {
            io->depth = b.read(bb.texture(res::kDepth));
            io->low = b.write(b.create("ism_blur_y", rawDesc), gi::TextureUsage::StorageWrite);
          }
          // An earlier effect's "indirect" (its neutral 0 when none), added to the far field.
          io->prior = b.readOptional(res::kIndirect);
          io->indirect = b.write(b.create(res::kIndirect, gi::TextureDesc{kOutFormat}),
                                 gi::TextureUsage::StorageWrite);
        },
        [this, io, c, frame, nearest, linear, params](gi::PassContext& pc) {
          const VkExtent2D e = pc.extent(io->indirect), low = pc.extent(io->half);
          gi::vk::DescriptorWriter x(blurX_);
          x.buffer("Frame", frame)
              .buffer("ism", params)
              .texture("inRaw", pc.view(io->raw), nearest)
              .image("outRaw", pc.view(io->half));
          pc.dispatch(blurX_, x, low, kGroupX, kGroupY);
          gi::vk::storageWriteToSampledRead(pc.cmd(), pc.image(io->half));
          if (c.scale > 1) {  // y at the gathering's resolution, then upsampled and reflected
            gi::vk::DescriptorWriter y(blurY_);
            y.buffer("Frame", frame)
                .buffer("ism", params)
                .texture("inRaw", pc.view(io->half), nearest, VK_IMAGE_LAYOUT_GENERAL)
                .image("outRaw", pc.view(io->low));
            pc.dispatch(blurY_, y, low, kGroupX, kGroupY);
            gi::vk::storageWriteToSampledRead(pc.cmd(), pc.image(io->low));
            gi::vk::DescriptorWriter u(upsample_);
            u.buffer("Frame", frame)
                .buffer("ism", params)
                .texture("lowRaw", pc.view(io->low), nearest, VK_IMAGE_LAYOUT_GENERAL)
                .texture("gDepth", pc.view(io->depth), nearest)
                .texture("giGBuffer", pc.view(io->gbuffer), nearest)
                .texture("priorIndirect", pc.view(io->prior), linear)
                .image("outIndirect", pc.view(io->indirect));
            pc.dispatch(upsample_, u, e, kGroupX, kGroupY);
            return;
          }
          gi::vk::DescriptorWriter y(blurY_);
          y.buffer("Frame", frame)
              .buffer("ism", params)
              .texture("inRaw", pc.view(io->half), nearest, VK_IMAGE_LAYOUT_GENERAL)
              .texture("giGBuffer", pc.view(io->gbuffer), nearest)
              .texture("priorIndirect", pc.view(io->prior), linear)
              .image("outIndirect", pc.view(io->indirect));
          pc.dispatch(blurY_, y, e, kGroupX, kGroupY);
        });
    bb.put(res::kIndirect, io->indirect);
  }

 private:
  // The surface points' count (two vec4 each) into the parameter block.
  void uploadPointCount(gi::PassContext& pc, gi::BufferHandle points) {
    const VkDeviceSize count = pc.bufferSize(points) / (2 * sizeof(glm::vec4));
    uploaded_.atlas.w = float(count);
    uniforms_.write(&uploaded_.atlas, sizeof(glm::vec4), offsetof(gi::ism::Uniforms, atlas));
  }

  // Splats bounce `bounce`'s VPLs' point subsets into their tiles (mip 0).
  template <class IoT>
  void splat(gi::PassContext& pc, const IoT& io, const Config& c, int bounce) {
    splatTiles(pc, splat_, io.vpls, io, bounce * c.vpls, bounce * c.vpls, c.vpls);
  }
  // Splats `count` VPLs of table `vpls` from `first` into tiles from `firstTile` with `pipeline`
  // (ism_splat.comp: paraboloids, or orthographic for the environment VPLs).
  template <class IoT>
  void splatTiles(gi::PassContext& pc, const gi::vk::Pipeline& pipeline, gi::BufferHandle vpls,
                  const IoT& io, int first, int firstTile, int count) {
    gi::vk::DescriptorWriter w(pipeline);
    w.buffer("ism", uniforms_.handle())
        .buffer("Vpls", pc.buffer(vpls))
        .buffer("Points", pc.buffer(io.points))
        .image("atlas", pc.view(io.atlas, gi::Subresource::mipLevel(0)));
    pc.dispatch(pipeline, w, {uint32_t(cfg_.perIsm), uint32_t(count)}, 256, 1,
                SplatPush{first, firstTile});
  }

  // Pull-push over tiles [first, end) (one bounce's VPLs, or the environment VPLs).
  template <class IoPtr>
  void addPullPush(gi::FrameGraph& graph, const IoPtr& io, const Config& c, int first, int end,
                   const std::string& name) {
    if (c.levels == 0) return;
    graph.addPass(
        name,
        [&](gi::PassBuilder& b) {
          // Every level of a 64 x 64 block in one workgroup (ism_pull_push.comp), in place.
          io->atlas = b.read(io->atlas, gi::TextureUsage::StorageRead);
          io->atlas = b.write(io->atlas, gi::TextureUsage::StorageWrite);
        },
        [this, io, c, first, end](gi::PassContext& pc) {
          // Only the 64-texel block rows that hold the range's tile rows.
          const int rowBegin = first / c.perRow * c.res / 64;
          const int rowEnd = ((end - 1) / c.perRow + 1) * c.res;  // texel row past the range
          gi::vk::DescriptorWriter w(pullPush_);
          w.buffer("ism", uniforms_.handle()).image("atlas", pc.view(io->atlas));
          pc.descriptors().bind(pc.cmd(), pullPush_, w);
          pullPush_.push(pc.cmd(), PullPushPush{first, end, rowBegin});
          const VkExtent2D e = pc.extent(io->atlas);
          vkCmdDispatch(pc.cmd(), (e.width + 63) / 64, uint32_t((rowEnd + 63) / 64 - rowBegin), 1);
        });
  }

  // Environment VPLs (seed 002 §5): sampled from the environment map (ism_env_vpl.comp), their
  // orthographic maps splatted into the tiles after the point VPLs' and pull-pushed; and
  // "ambient" published as nothing (alpha 1, rgb 0): the environment's light now arrives,
  // shadowed, with the gathering's "indirect", so the engine's unshadowed term must go.
  template <class IoPtr>
  void addEnvironmentVpls(gi::FrameGraph& graph, gi::EffectContext& ctx, const IoPtr& io) {
    const Config c = cfg_;
    gi::Blackboard& bb = graph.blackboard();
    io->envVpls = graph.importBuffer("ism_env_vpls", envBuffer_.handle(), envBuffer_.size());
    graph.addPass(
        "ism_env_vpl",
        [&](gi::PassBuilder& b) {
          io->envMap = b.read(bb.texture(res::kEnvironmentMap));
          io->envSampling =
              b.read(bb.buffer(res::kEnvironmentSampling), gi::BufferUsage::StorageRead);
          io->envVpls = b.write(io->envVpls, gi::BufferUsage::StorageWrite);
        },
        [this, io, c](gi::PassContext& pc) {
          gi::vk::DescriptorWriter w(envVpl_);
          w.buffer("ism", uniforms_.handle())
              .texture("giEnvironmentMap", pc.view(io->envMap), nearest_)
              .buffer("giEnvironment", pc.buffer(io->envSampling))
              .buffer("EnvVpls", pc.buffer(io->envVpls));
          pc.dispatch(envVpl_, w, {uint32_t(c.envPadded), 1}, 64, 1);
        });
    if (c.classic) {
      addClassicMaps(graph, ctx, io, {}, ClassicRange{"", 0, c.env, c.total(), true});
    } else {
      addEnvSplat(graph, io);
      addPullPush(graph, io, c, c.total(), c.total() + c.envPadded, "ism_env_pull_push");
    }
    graph.addPass(
        "ism_env_ambient",
        [&](gi::PassBuilder& b) {
          gi::TextureDesc one{kOutFormat, gi::SizeClass::Absolute, 1.0f, 1, 1};
          io->ambient = b.write(b.create("ism_ambient", one), gi::TextureUsage::TransferDst);
        },
        [io](gi::PassContext& pc) {
          const VkClearColorValue nothing{.float32 = {0.0f, 0.0f, 0.0f, 1.0f}};
          const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
          vkCmdClearColorImage(pc.cmd(), pc.image(io->ambient),
                               VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &nothing, 1, &range);
        });
    bb.put(res::kAmbient, io->ambient);
  }
  // The environment VPLs' orthographic ISMs: their point subsets splatted into their tiles.
  template <class IoPtr>
  void addEnvSplat(gi::FrameGraph& graph, const IoPtr& io) {
    const Config c = cfg_;
    graph.addPass(
        "ism_env_splat",
        [&](gi::PassBuilder& b) {
          io->envVpls = b.read(io->envVpls, gi::BufferUsage::Uniform);
          io->points = b.read(io->points, gi::BufferUsage::StorageRead);
          io->atlas = b.read(io->atlas, gi::TextureUsage::StorageRead);
          io->atlas = b.write(io->atlas, gi::TextureUsage::StorageWrite);
        },
        [this, io, c](gi::PassContext& pc) {
          splatTiles(pc, envSplat_, io->envVpls, *io, 0, c.total(), c.env);
        });
  }

  // The VPLs a classic-map pass pair draws: [first, first + count) of the point VPL table (one
  // bounce), or of the environment VPLs' (orthographic views), into tiles from firstTile.
  struct ClassicRange {
    std::string suffix;  // of the pass names
    int first = 0, count = 0, firstTile = 0;
    bool environment = false;
  };
  ClassicRange bounceRange(int bounce) const {
    const Config& c = cfg_;
    return {bounce == 0 ? "" : std::to_string(bounce + 1), bounce * c.vpls, c.vpls, bounce * c.vpls,
            false};
  }

  // Classic mode: the views of range r's VPLs (paraboloids, or orthographic for the environment
  // VPLs), written on the GPU from this frame's VPL table (no read-back: the maps are current,
  // not one frame late), then their maps drawn from the triangles into their tiles (the range
  // at tile 0 creates and clears the atlas).
  template <class IoPtr>
  void addClassicMaps(gi::FrameGraph& graph, gi::EffectContext& ctx, const IoPtr& io,
                      const gi::TextureDesc& atlas, const ClassicRange& r) {
    const std::string prefix = r.environment ? "ism_env" : "ism";
    const std::string views = prefix + "_classic_views" + r.suffix;
    // This pair's own views buffer (a shared member of io would name the last pair's by the
    // time the passes run: every pass is set up first).
    auto mine = std::make_shared<gi::BufferHandle>();
    graph.addPass(
        views,
        [&](gi::PassBuilder& b) {
          if (r.environment)
            io->envVpls = b.read(io->envVpls, gi::BufferUsage::Uniform);
          else
            io->vpls = b.read(io->vpls, gi::BufferUsage::Uniform);
          *mine =
              b.write(b.create(views, gi::BufferDesc{gi::kDrawViewStride * VkDeviceSize(r.count)}),
                      gi::BufferUsage::StorageWrite);
        },
        [this, io, r, mine](gi::PassContext& pc) {
          const gi::vk::Pipeline& p = r.environment ? envClassicViews_ : classicViews_;
          gi::vk::DescriptorWriter w(p);
          w.buffer("ism", uniforms_.handle())
              .buffer("Vpls", pc.buffer(r.environment ? io->envVpls : io->vpls))
              .buffer("Views", pc.buffer(*mine));
          pc.dispatch(p, w, {uint32_t(r.count), 1}, 64, 1,
                      ClassicViewsPush{r.first, r.count, r.firstTile});
        });
    graph.addPass(
        prefix + "_classic_sm" + r.suffix,
        [&](gi::PassBuilder& b) {
          ctx.scene().declareRead(b);
          *mine = b.read(*mine, gi::BufferUsage::Uniform);
          if (r.firstTile == 0) {
            io->atlas =
                b.write(b.create("ism_classic_atlas", atlas), gi::TextureUsage::DepthAttachment);
          } else {  // keeps the earlier tiles
            io->atlas = b.read(io->atlas, gi::TextureUsage::DepthAttachment);
            io->atlas = b.write(io->atlas, gi::TextureUsage::DepthAttachment);
          }
        },
        [this, io, r, mine, cx = &ctx](gi::PassContext& pc) {
          drawClassic(pc, *cx, *io, *mine, r);
        });
  }

  // Bounce `bounce` + 1's VPLs: bounce `bounce`'s VPLs' imperfect reflective shadow maps
  // (ism_irsm.glsl), then importance sampling over them (ism_bounce.comp).
  template <class IoPtr>
  void addBounce(gi::FrameGraph& graph, gi::EffectContext& ctx, const IoPtr& io, int bounce) {
    const Config c = cfg_;
    const std::string n = std::to_string(bounce + 1);
    const uint32_t entries = gi::ism::irsmEntries(c.perIsm), cellsPerVpl = (entries + 255) / 256;
    // This bounce's own IRSM buffers (a member of io would name the last bounce's by the time
    // the passes run: every pass is set up first).
    struct Irsm {
      gi::BufferHandle irsm, cells;
    };
    auto own = std::make_shared<Irsm>();
    graph.addPass(
        "ism_irsm" + n,
        [&](gi::PassBuilder& b) {
          io->points = b.read(io->points, gi::BufferUsage::StorageRead);
          io->atlas = b.read(io->atlas, gi::TextureUsage::Sampled, gi::Subresource::mipLevel(0));
          io->vpls = b.read(io->vpls, gi::BufferUsage::Uniform);
          own->irsm = b.write(b.create("ism_irsm" + n, gi::BufferDesc{VkDeviceSize(c.vpls) *
                                                                      entries * sizeof(glm::vec4)}),
                              gi::BufferUsage::StorageWrite);
          own->cells =
              b.write(b.create("ism_irsm_cells" + n,
                               gi::BufferDesc{VkDeviceSize(c.vpls) * cellsPerVpl * sizeof(float)}),
                      gi::BufferUsage::StorageWrite);
        },
        [this, io, own, c, bounce, entries,
         materials = ctx.scene().materials()](gi::PassContext& pc) {
          if (c.classic) {  // no splat pass sets the point count
            uploadPointCount(pc, io->points);
          }
          gi::vk::DescriptorWriter w(irsm_);
          w.buffer("ism", uniforms_.handle())
              .buffer("Vpls", pc.buffer(io->vpls))
              .buffer("Points", pc.buffer(io->points))
              .buffer("Materials", materials)
              .texture("maps", pc.view(io->atlas, gi::Subresource::mipLevel(0)), nearest_)
              .buffer("Irsm", pc.buffer(own->irsm))
              .buffer("Cells", pc.buffer(own->cells));
          pc.dispatch(irsm_, w, {entries, uint32_t(c.vpls)}, 256, 1,
                      IrsmPush{(bounce - 1) * c.vpls});
        });
    graph.addPass(
        "ism_bounce" + n,
        [&](gi::PassBuilder& b) {
          io->points = b.read(io->points, gi::BufferUsage::StorageRead);
          own->irsm = b.read(own->irsm, gi::BufferUsage::StorageRead);
          own->cells = b.read(own->cells, gi::BufferUsage::StorageRead);
          own->cells = b.write(own->cells, gi::BufferUsage::StorageWrite);
          // Adds this bounce's slots; the earlier bounces' stay.
          io->vpls = b.read(io->vpls, gi::BufferUsage::StorageRead);
          io->vpls = b.write(io->vpls, gi::BufferUsage::StorageWrite);
        },
        [this, io, own, bounce](gi::PassContext& pc) {
          gi::vk::DescriptorWriter w(bounce_);
          w.buffer("ism", uniforms_.handle())
              .buffer("Points", pc.buffer(io->points))
              .buffer("Irsm", pc.buffer(own->irsm))
              .buffer("Cdf", pc.buffer(own->cells))
              .buffer("VplsOut", pc.buffer(io->vpls));
          pc.dispatch(bounce_, w, {1, 1}, 1, 1, BouncePush{bounce});
        });
  }

  static float sceneExtent(gi::EffectContext& ctx) {
    glm::vec3 lo, hi;
    ctx.scene().bounds(lo, hi);
    const float e = glm::length(hi - lo);
    return std::isfinite(e) && e > 1e-6f ? e : 1.0f;
  }

  // Written while recording (the renderer waits for each frame before recording the next).
  void upload(gi::EffectContext& ctx, const gi::SettingValues& s) {
    const Config& c = cfg_;
    const float extent = sceneExtent(ctx);
    const float dMin = float(s[h_.distance_clamp]) * extent;
    const float k = float(c.block);
    gi::ism::Uniforms u{};
    u.rsm = glm::vec4(3 * c.rsm, 2 * c.rsm, c.vpls, c.padded);
    u.atlas = glm::vec4(c.res, c.perRow, c.perIsm, 0.0f);  // point count: set by ism_splat
    u.bias = glm::vec4(float(s[h_.bias]) * extent, float(s[h_.bias_slope]), classicNear(extent),
                       classicFar(extent));
    u.pull = glm::vec4(float(s[h_.pull_threshold]) * extent, float(s[h_.push_threshold]) * extent,
                       c.levels, extent);
    u.gather = glm::vec4(dMin * dMin, k, k * k, float(s[h_.strength]));
    u.blur =
        glm::vec4(float(s[h_.blur_tolerance]), 0.9f, float(s[h_.splat_scale]), float(c.total()));
    glm::vec3 lo, hi;
    ctx.scene().bounds(lo, hi);
    const glm::vec3 centre = 0.5f * (lo + hi);
    const float radius = 0.5f * extent;
    const bool finite =
        std::isfinite(centre.x) && std::isfinite(centre.y) && std::isfinite(centre.z);
    gi::ism::OrthoFit fit{finite ? centre : glm::vec3(0.0f), radius, radius};
    if (finite && s[h_.environment_fit_view]) {
      const gi::CameraView& cam = ctx.camera();
      fit = gi::ism::fitEnvironmentMaps(lo, hi, glm::inverse(cam.proj * cam.view), cam.position);
    }
    u.envSphere = glm::vec4(fit.centre, fit.radius);
    u.envDepth = glm::vec4(fit.depth, 0.0f, 0.0f, 0.0f);
    u.envVpls = glm::vec4(c.env, c.envPadded, c.total(), float(s[h_.environment_normal_offset]));
    u.nearField = glm::vec4(aoRange_, indirectRange_, 0.0f, 0.0f);
    uniforms_.write(&u, sizeof u);
    uploaded_ = u;
  }

  static float classicNear(float extent) { return 1e-4f * extent; }
  static float classicFar(float extent) { return 2.0f * extent; }

  template <class IoT>
  void drawRsm(gi::PassContext& pc, gi::EffectContext& ctx, const IoT& io, const Config& c) {
    gi::LightInfo light;
    light.radiance = glm::vec3(0.0f);  // no light: an all-black map, zero VPLs
    if (!ctx.lights().empty()) light = ctx.lights().front();
    glm::vec3 lo, hi;
    ctx.scene().bounds(lo, hi);
    const glm::vec3 center = 0.5f * (lo + hi);
    const float extent = sceneExtent(ctx);
    const float far = extent + 2.0f * glm::length(light.position - center);
    const uint32_t r = uint32_t(c.rsm);
    gi::SceneTargets t;
    t.depth = pc.view(io.rsmDepth);
    t.colors = {pc.view(io.rsmPos), pc.view(io.rsmNormal), pc.view(io.rsmFlux)};
    t.extent = pc.extent(io.rsmDepth);
    // Perspective faces rasterize triangles exactly (a paraboloid interpolates positions
    // linearly across the disk, which misplaces the texels of large triangles).
    std::vector<gi::SceneView> views;
    const float znear = 1e-3f * extent;
    const float outer = std::acos(std::clamp(light.cosOuter, -1.0f, 1.0f));
    if (light.type == gi::LightType::Directional) {
      views.push_back(gi::SceneView::orthographic(center - light.direction * extent,
                                                  light.direction, 0.5f * extent, 0.5f * extent,
                                                  1e-3f * extent, 2.0f * extent));
    } else if (light.type == gi::LightType::Spot && outer < glm::radians(60.0f)) {
      views.push_back(gi::SceneView::perspective(light.position, light.direction,
                                                 2.0f * outer + 0.02f, 1.0f, znear, far));
    } else if (light.type == gi::LightType::Spot) {
      views.push_back(gi::SceneView::paraboloid(light.position, light.direction, znear, far));
    } else {
      const auto faces = gi::SceneView::cube(light.position, znear, far);
      views.assign(faces.begin(), faces.end());
    }
    for (size_t i = 0; i < views.size(); ++i) {
      views[i].viewport = {{int32_t((i % 3) * r), int32_t((i / 3) * r)}, {r, r}};
      t.clear = i == 0;  // the first draw clears the whole map (3 x 2 faces)
      ctx.scene().drawRsm(pc, t, views[i], light);
    }
  }

  // Classic reference: range r's VPLs (their views written by ism_classic_views) as depth maps
  // drawn from the triangles, one atlas tile each.
  template <class IoT>
  void drawClassic(gi::PassContext& pc, gi::EffectContext& ctx, const IoT& io,
                   gi::BufferHandle views, const ClassicRange& r) {
    const Config& c = cfg_;
    std::vector<VkRect2D> tiles;
    for (int i = r.firstTile; i < r.firstTile + r.count; ++i)
      tiles.push_back({{int32_t((i % c.perRow) * c.res), int32_t((i / c.perRow) * c.res)},
                       {uint32_t(c.res), uint32_t(c.res)}});
    gi::SceneTargets t;
    t.depth = pc.view(io.atlas);
    t.extent = pc.extent(io.atlas);
    t.clear = r.firstTile == 0;
    ctx.scene().drawDepthFromBuffer(pc, t, pc.buffer(views), tiles);
  }

  Config cfg_;
  gi::vk::Pipeline vpl_, splat_, pullPush_, upsample_, irsm_, bounce_, gather_, blurX_, blurY_,
      atlasView_, classicViews_, envVpl_, envSplat_, envClassicViews_;
  VkSampler nearest_ = VK_NULL_HANDLE;
  gi::vk::Buffer uniforms_, vplBuffer_, envBuffer_;
  gi::ism::Uniforms uploaded_{};
  // publishedRange of the "ao" composed with the environment VPLs and of an earlier
  // "indirect" (addPasses; uploaded while recording).
  float aoRange_ = 0.0f, indirectRange_ = 0.0f;
  struct Handles {  // typed settings read every frame, found by name in prepare()
    gi::Setting<double> distance_clamp, bias, bias_slope, pull_threshold, push_threshold, strength,
        blur_tolerance, splat_scale, environment_normal_offset;
    gi::Setting<bool> environment_fit_view;
  } h_;
};

}  // namespace

GI_EFFECT_MODULE(IsmEffect)
