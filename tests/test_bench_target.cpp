// gi-bench --target: every configuration's lit image scored against one light quantity (AO
// effects judged by the lighting they modulate), and results.json's per-repetition values,
// which pair interleaved configurations repetition by repetition (docs/bench/ssdo/table1.sh).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench_support.h"
#include "process.h"
#include "test_support.h"

namespace gi {
namespace {

namespace fs = std::filesystem;

bool hasPlugin(const char* name) {
  return fs::exists(test::binPath(std::string("plugins/gi_effect_") + name + ".so"));
}

nlohmann::json sweep(const std::string& dir, const std::string& name, const std::string& args) {
  const std::string out = dir + "/" + name;
  auto r = test::runCommand(test::benchCommand("--quick --reps 3 " + args + " --cache '" + dir +
                                               "/cache' --out '" + out + "'"));
  EXPECT_EQ(r.exitCode, 0) << args << ": " << r.output;
  return nlohmann::json::parse(test::readAll(out + "/results.json"));
}

const nlohmann::json& row(const nlohmann::json& j, const std::string& effect) {
  for (const auto& r : j["results"])
    if (r["effect"] == effect) return r;
  ADD_FAILURE() << "no row for " << effect;
  return j["results"][0];
}

bool startsWith(const nlohmann::json& v, const std::string& prefix) {
  return v.get<std::string>().rfind(prefix, 0) == 0;
}

TEST(BenchTarget, LitImagesOfEveryEffectAgainstOneQuantity) {
  if (!hasPlugin("ssao") || !hasPlugin("ssdo")) GTEST_SKIP() << "ssao and ssdo plugins needed";
  const std::string dir = test::makeTempDir("bench-target");
  const std::string effects = "--effects none,ssao,ssdo ";
  const nlohmann::json own = sweep(dir, "own", effects);
  const nlohmann::json gi = sweep(dir, "gi", effects + "--target direct+indirect");
  const nlohmann::json direct = sweep(dir, "direct", effects + "--target direct");

  // Without --target each effect has its own target: SSAO's AO, the engine's direct light.
  EXPECT_EQ(row(own, "ssao")["compared"], "ao");
  EXPECT_TRUE(startsWith(row(own, "ssao")["reference"], "ao r=0.5"));
  EXPECT_TRUE(startsWith(row(own, "none")["reference"], "direct spp="));
  EXPECT_TRUE(startsWith(row(own, "ssdo")["reference"], "direct+indirect spp="));

  for (const auto& r : gi["results"]) {
    EXPECT_EQ(r["compared"], "lit") << r.dump();
    EXPECT_TRUE(startsWith(r["reference"], "direct+indirect spp=")) << r.dump();
  }
  // SSAO's AO cannot be read from the lit image: its declared score is the target's.
  EXPECT_EQ(row(gi, "ssao")["declared"], row(gi, "ssao")["reference"]);
  EXPECT_DOUBLE_EQ(row(gi, "ssao")["declared_nrmse"].get<double>(),
                   row(gi, "ssao")["nrmse"].get<double>());
  // The same references and images: SSDO keeps its score, the engine alone is now scored
  // against direct + indirect, and SSAO's lit image differs from the engine's.
  EXPECT_DOUBLE_EQ(row(gi, "ssdo")["nrmse"].get<double>(), row(own, "ssdo")["nrmse"].get<double>());
  EXPECT_NE(row(gi, "none")["nrmse"], row(own, "none")["nrmse"]);
  EXPECT_NE(row(gi, "ssao")["nrmse"], row(gi, "none")["nrmse"]);

  // --target direct: the engine alone is scored as without it; SSDO against direct light,
  // while its declared quantity stays its own (a light quantity is read from the lit image).
  EXPECT_DOUBLE_EQ(row(direct, "none")["nrmse"].get<double>(),
                   row(own, "none")["nrmse"].get<double>());
  EXPECT_TRUE(startsWith(row(direct, "ssdo")["reference"], "direct spp="));
  EXPECT_TRUE(startsWith(row(direct, "ssdo")["declared"], "direct+indirect spp="));
  EXPECT_DOUBLE_EQ(row(direct, "ssdo")["declared_nrmse"].get<double>(),
                   row(own, "ssdo")["nrmse"].get<double>());
  EXPECT_NE(row(direct, "ssdo")["nrmse"], row(own, "ssdo")["nrmse"]);
}

// An AO effect whose settings make it output light (obscurance's radiance transfer publishes
// "ambient", not "ao") declares a light quantity and is judged by its lit image, against direct
// + indirect light; under its AO settings the same effect is still read at "ao".
TEST(BenchTarget, AnAoEffectThatOutputsLightIsJudgedAsLight) {
  if (!hasPlugin("obscurance")) GTEST_SKIP() << "the obscurance plugin is not built";
  const std::string dir = test::makeTempDir("bench-ao-light");
  const nlohmann::json j =
      sweep(dir, "out", "--effects obscurance --grid obscurance.transfer=off,radiance");
  int seen = 0;
  for (const auto& r : j["results"]) {
    const std::string params = r["params"];
    if (params.find("transfer=radiance") != std::string::npos) {
      EXPECT_EQ(r["compared"], "lit") << r.dump();
      EXPECT_TRUE(startsWith(r["reference"], "direct+indirect spp=")) << r.dump();
      EXPECT_TRUE(startsWith(r["declared"], "direct+indirect spp=")) << r.dump();
      ++seen;
    } else if (params.find("transfer=off") != std::string::npos) {
      EXPECT_EQ(r["compared"], "ao") << r.dump();
      EXPECT_TRUE(startsWith(r["declared"], "obscurance sqrt r=0.5")) << r.dump();
      ++seen;
    }
  }
  EXPECT_EQ(seen, 2) << j.dump();
}

// Each interval keeps its repetitions in measurement order: their median is the reported one,
// and a pass's values sum, repetition by repetition, to the effect time.
TEST(BenchTarget, RepetitionValuesAreKeptInOrder) {
  if (!hasPlugin("ssao")) GTEST_SKIP() << "the ssao plugin is not built";
  const std::string dir = test::makeTempDir("bench-values");
  const nlohmann::json j = sweep(dir, "out", "--effects ssao --reps 4");
  const auto& r = j["results"][0];
  const std::vector<double> total = r["total_interval"]["values"];
  ASSERT_EQ(total.size(), 4u);
  std::vector<double> sorted = total;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_DOUBLE_EQ(r["total_ms"].get<double>(), (sorted[1] + sorted[2]) / 2);
  std::vector<double> effect(4, 0.0);
  for (const auto& p : r["passes"]) {
    const std::vector<double> v = p["interval"]["values"];
    ASSERT_EQ(v.size(), 4u) << p.dump();
    if (p["pass"].get<std::string>().rfind("ssao", 0) == 0)
      for (size_t k = 0; k < 4; ++k) effect[k] += v[k];
  }
  const std::vector<double> effectValues = r["effect_interval"]["values"];
  for (size_t k = 0; k < 4; ++k) EXPECT_NEAR(effectValues[k], effect[k], 1e-9) << k;
}

// --exclude-emitters: the default room's lamp (an emissive quad on the ceiling) and the pixels
// around it leave the comparison; nothing else changes.
TEST(BenchTarget, ExcludeEmittersLeavesTheLampOut) {
  const std::string dir = test::makeTempDir("bench-emitters");
  const nlohmann::json all = sweep(dir, "all", "--effects none");
  const nlohmann::json cut = sweep(dir, "cut", "--effects none --exclude-emitters");
  const auto &a = all["results"][0], &c = cut["results"][0];
  // The lamp is 0.5 x 0.4 on the 2 x 2 ceiling seen from 3.9 away: at 64x48 some tens of
  // pixels, with the one-pixel ring around it fewer than a tenth of the image.
  EXPECT_LT(c["pixels"].get<size_t>(), a["pixels"].get<size_t>());
  EXPECT_GT(c["pixels"].get<size_t>(), a["pixels"].get<size_t>() * 9 / 10);
  EXPECT_EQ(c["reference"], a["reference"]);
  EXPECT_NE(c["nrmse"], a["nrmse"]);
}

// The reference's noise: every row carries its floor (RMS standard error / normaliser) and the
// normaliser, which leaves the lamp's pixels out. A 4-spp reference is far too noisy for the
// engine alone's error (about 0.4 of the mean) and is rendered again with more samples until
// the floor is at most a quarter of it (then within the cap), or stops at --ref-spp-max and
// says so.
TEST(BenchTarget, ReferencesAreRefinedUntilTheirNoiseIsAQuarterOfTheError) {
  const std::string dir = test::makeTempDir("bench-ref-noise");
  const std::string args = "--effects none --target direct+indirect --ref-spp 4";
  const nlohmann::json fixed = sweep(dir, "fixed", args);  // --quick: no refinement
  const nlohmann::json refined = sweep(dir, "refined", args + " --ref-spp-max 2048");
  const nlohmann::json capped = sweep(dir, "capped", args + " --ref-spp-max 8");
  const auto &f = row(fixed, "none"), &r = row(refined, "none"), &c = row(capped, "none");
  std::printf("4 spp: NRMSE %.4f noise %.4f; refined to %d spp: NRMSE %.4f noise %.4f\n",
              f["nrmse"].get<double>(), f["noise_floor"].get<double>(),
              r["reference_spp"].get<int>(), r["nrmse"].get<double>(),
              r["noise_floor"].get<double>());
  EXPECT_EQ(f["reference_spp"].get<int>(), 4);
  EXPECT_GT(f["noise_floor"].get<double>(), 0.25 * f["nrmse"].get<double>());
  EXPECT_GT(r["reference_spp"].get<int>(), 4);
  EXPECT_LE(r["noise_floor"].get<double>(), 0.25 * r["nrmse"].get<double>());
  EXPECT_FALSE(r["noise_capped"].get<bool>());
  // The noise falls as 1 / sqrt(spp), and the NRMSE with it (part of it was the reference's).
  EXPECT_NEAR(r["noise_floor"].get<double>() / f["noise_floor"].get<double>() /
                  std::sqrt(4.0 / r["reference_spp"].get<double>()),
              1.0, 0.4);
  EXPECT_LT(r["nrmse"].get<double>(), f["nrmse"].get<double>());
  // The normaliser leaves the lamp out: fewer pixels than scored, a smaller mean.
  EXPECT_LT(r["normaliser_pixels"].get<size_t>(), r["pixels"].get<size_t>());
  EXPECT_EQ(c["reference_spp"].get<int>(), 8);
  EXPECT_TRUE(c["noise_capped"].get<bool>());
}

// Against the engine alone: the share of its error a configuration removes, and the share of
// the reference's indirect light it delivers. SSAO only darkens: it delivers less than none.
TEST(BenchTarget, RowsSayWhatTheyRecoverOfTheEngineAlonesError) {
  if (!hasPlugin("ssao")) GTEST_SKIP() << "ssao plugin needed";
  const std::string dir = test::makeTempDir("bench-recovered");
  const nlohmann::json j = sweep(dir, "out", "--effects none,ssao --target direct+indirect");
  const auto &none = row(j, "none"), &ssao = row(j, "ssao");
  EXPECT_DOUBLE_EQ(none["error_removed"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(none["indirect_delivered"].get<double>(), 0.0);
  EXPECT_NEAR(ssao["error_removed"].get<double>(),
              1.0 - ssao["nrmse"].get<double>() / none["nrmse"].get<double>(), 1e-12);
  EXPECT_LT(ssao["indirect_delivered"].get<double>(), 0.0);
  // The report says how loaded the machine was, and has the recovered section.
  const std::string report = test::readAll(dir + "/out/report.md");
  EXPECT_NE(report.find("Load average (1 min) at the start and end: "), std::string::npos);
  EXPECT_EQ(report.find("Load average (1 min) at the start and end: unknown"), std::string::npos);
  EXPECT_NE(report.find("## Missing light recovered"), std::string::npos);
  // The room defines regions: each is scored apart, the faces of the room are disjoint and
  // cover part of the image, the floor is seen.
  const auto& regions = none["regions"];
  ASSERT_EQ(regions.size(), 7u);
  size_t faces = 0;
  for (size_t k = 0; k < 5; ++k) faces += regions[k]["pixels"].get<size_t>();
  EXPECT_EQ(regions[0]["name"], "floor");
  EXPECT_GT(regions[0]["pixels"].get<size_t>(), 0u);
  EXPECT_LE(faces, none["pixels"].get<size_t>());
  EXPECT_GT(regions[0]["nrmse"].get<double>(), 0.0);
  EXPECT_NE(report.find("## Errors by region"), std::string::npos);
  // Without an engine-alone row of the same target there is nothing to compare with.
  const nlohmann::json alone = sweep(dir, "alone", "--effects ssao --target direct+indirect");
  EXPECT_FALSE(row(alone, "ssao").contains("error_removed"));
}

// --no-emitter-light: the direct+indirect reference in which the default room's lamp (an
// emissive quad) is seen but lights nothing, as for effects whose light comes from the lights
// only; labelled, cached apart from the lit one, and a different score.
TEST(BenchTarget, NoEmitterLightGivesItsOwnReference) {
  const std::string dir = test::makeTempDir("bench-dark-emitters");
  const std::string args = "--effects none --target direct+indirect";
  const nlohmann::json lit = sweep(dir, "lit", args);
  const nlohmann::json dark = sweep(dir, "dark", args + " --no-emitter-light");
  const std::string litRef = row(lit, "none")["reference"],
                    darkRef = row(dark, "none")["reference"];
  EXPECT_EQ(litRef.find("dark-emitters"), std::string::npos) << litRef;
  EXPECT_NE(darkRef.find("dark-emitters"), std::string::npos) << darkRef;
  EXPECT_NE(row(dark, "none")["nrmse"], row(lit, "none")["nrmse"]);
  std::printf("engine alone vs direct+indirect: NRMSE %.4f lit emitters, %.4f dark\n",
              row(lit, "none")["nrmse"].get<double>(), row(dark, "none")["nrmse"].get<double>());
}

// --ref-bounces: direct+indirect references with more diffuse bounces (for ism.bounces),
// labelled and cached apart; the engine alone, with no indirect light at all, is farther from
// the brighter 3-bounce reference.
TEST(BenchTarget, RefBouncesGivesItsOwnReference) {
  const std::string dir = test::makeTempDir("bench-ref-bounces");
  const std::string args = "--effects none --target direct+indirect";
  const nlohmann::json one = sweep(dir, "one", args);
  const nlohmann::json three = sweep(dir, "three", args + " --ref-bounces 3");
  const std::string oneRef = row(one, "none")["reference"],
                    threeRef = row(three, "none")["reference"];
  EXPECT_EQ(oneRef.find("bounces="), std::string::npos) << oneRef;
  EXPECT_NE(threeRef.find("bounces=3"), std::string::npos) << threeRef;
  std::printf("engine alone vs direct+indirect: NRMSE %.4f (1 bounce), %.4f (3 bounces)\n",
              row(one, "none")["nrmse"].get<double>(), row(three, "none")["nrmse"].get<double>());
  EXPECT_GT(row(three, "none")["nrmse"].get<double>(), row(one, "none")["nrmse"].get<double>());
}

TEST(BenchTarget, BadTargetFailsBeforeRendering) {
  const std::string dir = test::makeTempDir("bench-target-bad");
  const std::string out = dir + "/out";
  for (const auto& [args, needle] : std::vector<std::pair<std::string, std::string>>{
           {"--target ao", "--target: expects direct or direct+indirect, got 'ao'"},
           {"--target direct --ao-split", "--target: excludes --ao-split"},
           {"--ref-bounces 0", "--ref-bounces:"}}) {
    auto r = test::runCommand(
        test::benchCommand("--quick " + args + " --cache '" + dir + "/cache' --out '" + out + "'"));
    EXPECT_NE(r.exitCode, 0) << args << ": " << r.output;
    EXPECT_NE(r.output.find(needle), std::string::npos) << args << ": " << r.output;
    EXPECT_FALSE(fs::exists(out)) << args;
    EXPECT_FALSE(fs::exists(dir + "/cache")) << args;
  }
}

}  // namespace
}  // namespace gi
