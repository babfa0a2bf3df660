// gi-reference: CPU ground-truth renderer (Embree). Estimates ambient occlusion (optionally split
// by what a screen-space method can see), obscurance, the Alchemy obscurance integral, direct
// light or direct + one bounce for exactly the scene and camera gi-render uses, and writes the
// float image, its per-pixel standard error and an 8-bit preview. Prints the time taken, the
// samples per pixel reached and the mean standard error.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "cli.h"
#include "gi/errors.h"
#include "gi/image_io.h"
#include "gi/reference/reference.h"
#include "gi/scene_io.h"

namespace {

namespace ref = gi::reference;

const char* kUsage =
    "usage: gi-reference --scene FILE|default --out IMAGE.pfm [options]\n"
    "  --quantity Q           ao, obscurance, alchemy, direct, direct+indirect, depth, normal,\n"
    "                         ao-split, alchemy-disk (default ao)\n"
    "  --radius R             AO / obscurance / Alchemy radius in world units (default 0.5)\n"
    "  --spp N                maximum samples per pixel (default 64)\n"
    "  --noise-target E       stop early once the mean per-pixel standard error is <= E\n"
    "  --min-spp N            samples before the noise target is checked (default 16)\n"
    "  --bounces N            direct+indirect: diffuse bounces, 1..8 (default 1)\n"
    "  --no-emitter-light     direct+indirect: emissive surfaces are seen but light nothing\n"
    "                         (the renderer's effects take light from the lights only)\n"
    "  --width W --height H   image size (default 320x240)\n"
    "  --seed S               random seed (default 1); a seed always gives the same image\n"
    "  --threads T            worker threads (default: all cores); does not change the image\n"
    "  --time T               animation clock in seconds, as gi-render --time (default 0)\n"
    "  --membership M         obscurance membership mu: sqrt (default), linear, smoothstep,\n"
    "                         step (= AO), exp\n"
    "  --alchemy-sigma S      Alchemy intensity sigma (default 1)\n"
    "  --alchemy-u U          Alchemy falloff knee u (default 0: the paper's eq. 10 form)\n"
    "  --alchemy-epsilon E    Alchemy epsilon (default 1e-4)\n"
    "  --alchemy-contrast K   Alchemy contrast k (default 1)\n"
    "  --alchemy-bias B       alchemy-disk bias beta: max(0, v.n - beta z) (default 0)\n"
    "  --out FILE.pfm         the estimate (float RGB)\n"
    "  --stderr-out FILE.pfm  per-pixel standard error (default: <out>.stderr.pfm)\n"
    "  --png FILE.png         8-bit preview (grey for AO-like quantities, tonemapped light)\n"
    "  --gbuffer PREFIX       also write PREFIX_depth.pfm (reverse-Z depth, view z, 1 on "
    "geometry),\n"
    "                         PREFIX_normal.pfm (view space), PREFIX_position.pfm (world)\n"
    "  --exposure E           preview exposure for the lighting quantities (default 1)\n"
    "ao-split: --out holds AO_full (= ao); also written: <out>.visible.pfm (AO_visible, the AO\n"
    "of the depth layer alone), <out>.offscreen.pfm and <out>.hidden.pfm (occluded fractions by\n"
    "off-screen and hidden occluders), <out>.split.stderr.pfm (their standard errors, rgb) and,\n"
    "with --png, <png>.visible.png, <png>.offscreen.png, <png>.hidden.png (grey previews)\n"
    "  --quiet                no progress lines\n";

struct Options {
  std::string scene, out, png, stderrOut, gbuffer;
  ref::Settings settings;
  double time = 0.0;
  float exposure = 1.0f;
  bool quiet = false;
};

Options parseArgs(int argc, char** argv) {
  Options o;
  ref::Settings& s = o.settings;
  for (gi::cli::Args a("gi-reference", argc, argv); a.next();) {
    if (a.is("--help") || a.is("-h")) {
      std::fputs(kUsage, stdout);
      std::exit(0);
    } else if (a.is("--scene"))
      o.scene = a.value();
    else if (a.is("--out"))
      o.out = a.value();
    else if (a.is("--png"))
      o.png = a.value();
    else if (a.is("--stderr-out"))
      o.stderrOut = a.value();
    else if (a.is("--gbuffer"))
      o.gbuffer = a.value();
    else if (a.is("--quantity"))
      s.quantity = ref::parseQuantity(a.value());
    else if (a.is("--membership"))
      s.membership = ref::parseMembership(a.value());
    else if (a.is("--radius"))
      s.radius = float(a.numberAbove(0, 1e9));
    else if (a.is("--spp"))
      s.spp = uint32_t(a.integer(1, 1 << 24));
    else if (a.is("--no-emitter-light"))
      s.emitterLight = false;
    else if (a.is("--bounces"))
      s.bounces = uint32_t(a.integer(1, ref::kMaxBounces));
    else if (a.is("--min-spp"))
      s.minSpp = uint32_t(a.integer(1, 1 << 24));
    else if (a.is("--noise-target"))
      s.noiseTarget = a.number(0, 1e9);
    else if (a.is("--width"))
      s.width = uint32_t(a.integer(1, 16384));
    else if (a.is("--height"))
      s.height = uint32_t(a.integer(1, 16384));
    else if (a.is("--seed"))
      s.seed = uint64_t(a.integer(0, std::numeric_limits<int64_t>::max()));
    else if (a.is("--threads"))
      s.threads = unsigned(a.integer(1, 1024));
    else if (a.is("--time"))
      o.time = a.number(-1e9, 1e9);
    else if (a.is("--alchemy-sigma"))
      s.alchemy.sigma = float(a.number(0, 1e9));
    else if (a.is("--alchemy-u"))
      s.alchemy.u = float(a.number(0, 1e9));
    else if (a.is("--alchemy-epsilon"))  // 0 only with --alchemy-u > 0 (checked by render)
      s.alchemy.epsilon = float(a.number(0, 1));
    else if (a.is("--alchemy-contrast"))
      s.alchemy.contrast = float(a.number(1e-6, 1e6));
    else if (a.is("--alchemy-bias"))
      s.alchemy.bias = float(a.number(0, 1e9));
    else if (a.is("--exposure"))
      o.exposure = float(a.number(0, 1e6));
    else if (a.is("--quiet"))
      o.quiet = true;
    else
      a.unknown();
  }
  auto usageError = [](const std::string& message) {
    gi::cli::usageError("gi-reference", "", message);
  };
  if (o.scene.empty()) usageError("--scene is required");
  if (o.out.empty()) usageError("--out is required");
  auto requireExt = [](const std::string& path, const char* ext) {
    if (!path.empty() && std::filesystem::path(path).extension() != ext)
      throw gi::Error(gi::ErrorKind::Usage, path, std::string("output must end in ") + ext);
  };
  requireExt(o.out, ".pfm");
  requireExt(o.stderrOut, ".pfm");
  requireExt(o.png, ".png");
  if (o.stderrOut.empty())
    o.stderrOut = (std::filesystem::path(o.out).replace_extension(".stderr.pfm")).string();
  return o;
}

// "dir/x.pfm" + ".visible" -> "dir/x.visible.pfm".
std::string withSuffix(const std::string& path, const std::string& suffix) {
  std::filesystem::path p(path);
  const std::string ext = p.extension().string();
  return p.replace_extension(suffix + ext).string();
}

// A single-channel plane of an RGBA image, repeated in rgb (alpha kept).
gi::ImageRGBA32F grey(const gi::ImageRGBA32F& image, int c) {
  gi::ImageRGBA32F out = image;
  for (size_t i = 0; i + 3 < out.pixels.size(); i += 4)
    out.pixels[i] = out.pixels[i + 1] = out.pixels[i + 2] = image.pixels[i + size_t(c)];
  return out;
}

int run(const Options& o) {
  std::vector<std::pair<std::string, const gi::ImageRGBA32F*>> floats;
  std::vector<std::string> outputs = {o.out, o.stderrOut};
  if (!o.png.empty()) outputs.push_back(o.png);
  const bool split = o.settings.quantity == ref::Quantity::AOSplit;
  static const char* kSplitNames[3] = {".visible", ".offscreen", ".hidden"};
  if (split) {
    for (const char* suffix : kSplitNames) {
      outputs.push_back(withSuffix(o.out, suffix));
      if (!o.png.empty()) outputs.push_back(withSuffix(o.png, suffix));
    }
    outputs.push_back(withSuffix(o.out, ".split.stderr"));
  }
  if (!o.gbuffer.empty())
    for (const char* suffix : {"_depth.pfm", "_normal.pfm", "_position.pfm"})
      outputs.push_back(o.gbuffer + suffix);
  for (const std::string& path : outputs) gi::cli::checkOutputWritable(path);

  gi::Scene scene = gi::loadScene(o.scene);
  for (const std::string& w : scene.warnings)
    std::fprintf(stderr, "gi-reference: warning: %s\n", w.c_str());
  scene.animate(o.time);  // as gi-render poses the scene (Renderer::setTime)

  ref::Settings settings = o.settings;
  if (!o.quiet)
    settings.progress = [](const ref::Progress& p) {
      std::fprintf(stderr, "gi-reference: %u spp, mean standard error %.6g, %.2f s\n", p.spp,
                   p.meanStdError, p.seconds);
    };
  const ref::Result r = ref::render(scene, settings);

  floats.push_back({o.out, &r.value});
  floats.push_back({o.stderrOut, &r.stdError});
  std::vector<gi::ImageRGBA32F> splitPlanes;
  if (split) {
    for (int c = 0; c < 3; ++c) splitPlanes.push_back(grey(r.split, c));
    for (int c = 0; c < 3; ++c)
      floats.push_back({withSuffix(o.out, kSplitNames[c]), &splitPlanes[size_t(c)]});
    floats.push_back({withSuffix(o.out, ".split.stderr"), &r.splitStdError});
  }
  if (!o.gbuffer.empty()) {
    floats.push_back({o.gbuffer + "_depth.pfm", &r.depth});
    floats.push_back({o.gbuffer + "_normal.pfm", &r.normal});
    floats.push_back({o.gbuffer + "_position.pfm", &r.position});
  }
  // Each file is written through a temporary name; if a later one fails, the earlier ones are
  // removed so no partial set of outputs is left behind.
  std::vector<std::string> written;
  try {
    for (const auto& [path, image] : floats) {
      gi::writePfm(path, *image);
      written.push_back(path);
    }
    if (!o.png.empty()) {
      gi::writePng(o.png, ref::preview(r.value, settings.quantity, o.exposure));
      written.push_back(o.png);
      if (split)
        for (int c = 0; c < 3; ++c) {
          const std::string path = withSuffix(o.png, kSplitNames[c]);
          gi::writePng(path, ref::previewChannel(r.split, c));
          written.push_back(path);
        }
    }
  } catch (...) {
    std::error_code ec;
    for (const std::string& path : written) std::filesystem::remove(path, ec);
    throw;
  }

  std::printf("scene %s, %ux%u, %zu triangles, quantity %s", o.scene.c_str(), settings.width,
              settings.height, r.triangles, ref::quantityName(settings.quantity));
  if (settings.quantity == ref::Quantity::AO || settings.quantity == ref::Quantity::Alchemy ||
      settings.quantity == ref::Quantity::AlchemyDisk ||
      settings.quantity == ref::Quantity::Obscurance || split)
    std::printf(", radius %g", double(settings.radius));
  if (settings.quantity == ref::Quantity::Obscurance)
    std::printf(", membership %s", ref::membershipName(settings.membership));
  if (settings.quantity == ref::Quantity::DirectIndirect)
    std::printf(", bounces %u%s", settings.bounces,
                settings.emitterLight ? "" : ", emitters light nothing");
  std::printf("\n");
  std::printf("time %.3f s, %u samples per pixel, mean standard error %.6g (%zu geometry pixels)\n",
              r.seconds, r.spp, r.meanStdError, r.geometryPixels);
  if (split) {
    const ref::AoSplitSummary m = ref::summarizeAoSplit(r);
    std::printf(
        "ao-split: mean AO_full %.6g, AO_visible %.6g; occluded fraction by visible %.6g, "
        "off-screen %.6g, hidden %.6g; screen-space limit NRMSE(AO_visible vs AO_full) %.6g\n",
        m.aoFull, m.aoVisible, m.visible, m.offscreen, m.hidden, m.limitNrmse);
    const double occluded = double(std::max<uint64_t>(r.splitOccluded, 1));
    std::printf(
        "ao-split: of the occluded rays, %.4g%% counted visible through a layer surface behind "
        "their first hit, %.4g%% counted hidden with the first hit in front of the layer "
        "(sub-pixel)\n",
        100.0 * double(r.splitVisibleBehind) / occluded,
        100.0 * double(r.splitHiddenInFront) / occluded);
  }
  for (const std::string& path : written) std::printf("wrote %s\n", path.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return gi::cli::runMain("gi-reference", [&] { return run(parseArgs(argc, argv)); });
}
