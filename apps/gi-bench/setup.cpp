#include "setup.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli.h"
#include "gi/input_file.h"
#include "gi/scene_hash.h"
#include "gi/scene_io.h"
#include "progress.h"
#include "quantity.h"

namespace gi_bench {

namespace {

uint64_t fnv1a(const std::string& s, uint64_t h = 1469598103934665603ULL) {
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ULL;
  return h;
}

std::string cacheStem(const Options& o, const LoadedScene& s, const ReferenceKey& k, uint32_t spp) {
  std::ostringstream key;
  // The reference code's version and the loaded scene's content (every file it read: meshes,
  // textures, environment map), beside the scene file itself.
  key << "gi-bench-reference-v3|" << ref::kVersion << '|' << gi::sceneContentHash(s.scene) << '|'
      << s.contents.size() << '|';
  const gi::CameraView cam = gi::activeCamera(s.scene, float(o.width) / float(o.height));
  const float* v = &cam.view[0][0];
  const float* p = &cam.proj[0][0];
  char buf[32];
  for (int i = 0; i < 16; ++i) {
    std::snprintf(buf, sizeof buf, "%a,%a,", double(v[i]), double(p[i]));
    key << buf;
  }
  key << '|' << o.width << 'x' << o.height << '|' << gi::bench::keyText(k.spec) << '|' << spp << '|'
      << o.refSeed << '|' << s.scene.triangleCount() << (o.emitterLight ? "" : "|dark-emitters")
      << "|bounces" << o.refBounces;
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx",
                static_cast<unsigned long long>(fnv1a(s.contents, fnv1a(key.str()))));
  return (fs::path(o.cache) / hex).string();
}

}  // namespace

Reference computeReference(const Options& o, const LoadedScene& s, const ReferenceKey& k,
                           uint32_t spp) {
  if (spp == 0) spp = o.refSpp;
  const std::string stem = cacheStem(o, s, k, spp);
  Reference r;
  if (fs::exists(stem + ".json")) {
    try {
      std::ifstream in(stem + ".json");
      const nlohmann::json meta = nlohmann::json::parse(in);
      r.value = gi::readPfm(stem + ".value.pfm");
      r.depth = gi::readPfm(stem + ".depth.pfm");
      r.stdError = gi::readPfm(stem + ".stderr.pfm");
      if (k.spec.quantity == ref::Quantity::AOSplit) r.split = gi::readPfm(stem + ".split.pfm");
      r.spp = meta.at("spp");
      r.meanStdError = meta.at("mean_stderr");
      r.seconds = meta.at("seconds");
      r.cached = true;
      if (r.value.width == int(o.width) && r.value.height == int(o.height) &&
          r.stdError.width == r.value.width && r.stdError.height == r.value.height &&
          (k.spec.quantity != ref::Quantity::AOSplit ||
           (r.split.width == r.value.width && r.split.height == r.value.height)))
        return r;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "gi-bench: warning: %s: unreadable cache entry, recomputing (%s)\n",
                   stem.c_str(), e.what());
    }
  }
  ref::Settings rs;
  rs.width = o.width;
  rs.height = o.height;
  gi::bench::apply(k.spec, rs);
  rs.spp = spp;
  rs.minSpp = std::min(rs.minSpp, spp);
  rs.seed = o.refSeed;
  rs.emitterLight = o.emitterLight;
  rs.bounces = o.refBounces;
  ref::Result res = ref::render(s.scene, rs);
  r = Reference{res.value, res.depth,        res.stdError, res.split,
                res.spp,   res.meanStdError, res.seconds,  false};
  fs::create_directories(o.cache);
  // The metadata is written last: its presence marks a complete entry.
  gi::writePfm(stem + ".value.pfm", r.value);
  gi::writePfm(stem + ".depth.pfm", r.depth);
  gi::writePfm(stem + ".stderr.pfm", r.stdError);
  if (k.spec.quantity == ref::Quantity::AOSplit) gi::writePfm(stem + ".split.pfm", r.split);
  nlohmann::json meta = {{"scene", s.name},
                         {"quantity", gi::bench::label(k.spec)},
                         {"key", gi::bench::keyText(k.spec)},
                         {"width", o.width},
                         {"height", o.height},
                         {"spp", r.spp},
                         {"seed", o.refSeed},
                         {"mean_stderr", r.meanStdError},
                         {"seconds", r.seconds}};
  gi::cli::writeFileAtomic(stem + ".json", meta.dump(2) + "\n");
  return r;
}

std::vector<std::string> splitPlus(const std::string& item) {
  if (item == "none") return {};
  std::vector<std::string> out;
  std::string part;
  std::istringstream in(item);
  while (std::getline(in, part, '+'))
    if (!part.empty()) out.push_back(part);
  return out;
}

std::string joinList(const std::vector<std::string>& items) {
  std::string s;
  for (const auto& n : items) s += (s.empty() ? "" : ", ") + n;
  return s;
}

std::string knownEffects(const gi::EffectRegistry& registry) {
  const std::string s = joinList(registry.names());
  return s.empty() ? "none found" : s;
}

std::string formatDouble(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string nowString() {
  const std::time_t t = std::time(nullptr);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M:%S UTC", std::gmtime(&t));
  return buf;
}

void loadInputs(const Options& o, Setup& s) {
  s.registry.scanDefaultLocations();
  for (const std::string& name : o.scenes) {
    LoadedScene ls{name, gi::loadScene(name), "default"};
    if (name != "default") ls.contents = gi::readInputFile(name, "scene file");
    for (const std::string& w : ls.scene.warnings)
      std::fprintf(stderr, "gi-bench: warning: %s\n", w.c_str());
    s.scenes.push_back(std::move(ls));
  }
  for (const std::string& given : o.presets) {
    if (given != "all") s.presetNames.push_back(given);
    if (given == "all") {
      const std::vector<std::string> all = gi::presetNames();
      if (all.empty())
        usageError("--presets",
                   "'all': no preset found (searched: " + joinList(gi::presetLocations()) + ")");
      s.presetNames.insert(s.presetNames.end(), all.begin(), all.end());
    }
  }
  for (const std::string& p : s.presetNames) {
    if (p == "none") {
      s.presets.emplace_back();
      continue;
    }
    auto preset = std::make_unique<gi::Preset>(gi::loadPreset(p));
    gi::validatePreset(*preset, s.registry);
    s.presets.push_back(std::move(preset));
  }
}

std::vector<std::string> effectItems(const Options& o, const gi::EffectRegistry& registry) {
  std::vector<std::string> items;
  if (o.effects) {
    for (const std::string& item : *o.effects)
      if (item == "all") {
        const std::vector<std::string> names = registry.names();
        items.insert(items.end(), names.begin(), names.end());
      } else {
        items.push_back(item);
      }
  } else
    items = {registry.has("ssao") ? "ssao" : "none"};
  if (items.empty()) items = {"none"};
  for (const std::string& item : items) {
    if (item != "none" && (item.empty() || item.front() == '+' || item.back() == '+' ||
                           item.find("++") != std::string::npos))
      usageError("--effects", "'" + item + "' has an empty effect name (sets join names with '+')");
    const std::vector<std::string> set = splitPlus(item);
    for (size_t k = 0; k < set.size(); ++k)
      if (std::find(set.begin(), set.begin() + long(k), set[k]) != set.begin() + long(k))
        usageError("--effects", "'" + set[k] + "' appears twice in '" + item + "'");
  }
  for (const std::string& item : items)
    for (const std::string& e : splitPlus(item))
      if (item != "recommended" && !registry.has(e))
        usageError("--effects", "unknown effect '" + e + "' (known: " + knownEffects(registry) +
                                    "; plugins are loaded from <bin>/plugins and GI_PLUGIN_PATH)");
  return items;
}

gi::vk::Context makeContext(const Options& o) {
  gi::vk::ContextOptions opts = gi::vk::ContextOptions::fromEnvironment();
  opts.validation = o.validation;
  if (!o.device.empty()) opts.device = o.device;
  return gi::vk::Context(opts);
}

std::map<ReferenceKey, Reference> computeReferences(const Options& o, const Setup& s,
                                                    const std::vector<ReferenceKey>& keys) {
  std::map<ReferenceKey, Reference> refs;
  ProgressBar bar(o.progress, "references", keys.size());
  for (const ReferenceKey& k : keys) {
    if (refs.count(k)) continue;
    refs[k] = computeReference(o, s.scenes[k.scene], k);
    bar.step(s.scenes[k.scene].name + " " + gi::bench::label(k.spec) +
             (refs[k].cached ? " (cached)" : ""));
  }
  return refs;
}

}  // namespace gi_bench
