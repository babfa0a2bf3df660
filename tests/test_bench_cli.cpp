// gi-bench end to end: the --quick smoke sweep writes every output with finite metrics; bad
// input fails before rendering and writes nothing; --calibrate writes a preset gi-render loads,
// whose configuration measures within the budget.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "bench_support.h"
#include "gi/effect_registry.h"
#include "gi/image_io.h"
#include "process.h"
#include "test_support.h"

namespace gi {
namespace {

namespace fs = std::filesystem;

std::string bench(const std::string& args) {
  return test::benchCommand(args);
}

using test::readAll;
using test::splitCsvLine;

bool hasSsao() {
  return fs::exists(test::binPath("plugins/gi_effect_ssao.so"));
}

TEST(BenchCli, QuickSweepWritesFiniteResults) {
  const std::string dir = test::makeTempDir("bench-quick");
  const std::string out = dir + "/out";
  auto r = test::runCommand(bench("--quick --cache '" + dir + "/cache' --out '" + out + "'"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  for (const char* f : {"results.csv", "results.json", "report.md"})
    EXPECT_TRUE(fs::exists(out + "/" + f)) << f;
  // Every plot twice: SVG and its PNG twin (drawn by gi-bench's rasteriser: not blank, the
  // series colour present).
  size_t svgs = 0, pngs = 0;
  for (const auto& e : fs::directory_iterator(out + "/plots")) {
    if (e.path().extension() == ".png") {
      const ImageRGBA8 img = readPng(e.path().string());
      EXPECT_EQ(img.width, 760);
      EXPECT_EQ(img.height, 480);
      size_t blue = 0;
      for (size_t i = 0; i + 3 < img.pixels.size(); i += 4)
        blue += img.pixels[i] == 0x1f && img.pixels[i + 1] == 0x77 && img.pixels[i + 2] == 0xb4;
      EXPECT_GT(blue, 50u) << e.path();
      EXPECT_TRUE(fs::exists(fs::path(e.path()).replace_extension(".svg"))) << e.path();
      ++pngs;
      continue;
    }
    EXPECT_EQ(e.path().extension(), ".svg");
    const std::string svg = readAll(e.path().string());
    EXPECT_NE(svg.find("</svg>"), std::string::npos);
    if (hasSsao()) {
      EXPECT_NE(svg.find("ssao.samples=16"), std::string::npos) << "points named by the setting";
      EXPECT_NE(svg.find("Pareto front"), std::string::npos);
    }
    ++svgs;
  }
  EXPECT_GE(svgs, 1u);
  EXPECT_EQ(pngs, svgs);
  for (const auto& e : fs::recursive_directory_iterator(out))
    EXPECT_EQ(e.path().string().find(".partial"), std::string::npos) << e.path();

  // CSV: header + one row per configuration, every metric a finite number.
  std::istringstream csv(readAll(out + "/results.csv"));
  std::string line;
  std::getline(csv, line);
  const std::vector<std::string> header = splitCsvLine(line);
  size_t rows = 0;
  while (std::getline(csv, line)) {
    const std::vector<std::string> cells = splitCsvLine(line);
    ASSERT_EQ(cells.size(), header.size()) << line;
    for (size_t i = 0; i < cells.size(); ++i)
      if ((header[i].ends_with("_ms") && header[i] != "passes_ms") || header[i] == "nrmse" ||
          header[i] == "ssim" || header[i].find("floor") != std::string::npos) {
        const double v = std::stod(cells[i]);
        EXPECT_TRUE(std::isfinite(v)) << header[i] << " in " << line;
        EXPECT_GE(v, header[i] == "ssim" ? -1.0 : 0.0) << header[i];
      }
    EXPECT_EQ(line.find("nan"), std::string::npos) << line;
    ++rows;
  }
  EXPECT_GE(rows, 1u);
  if (hasSsao()) {
    EXPECT_GE(rows, 2u) << "--quick sweeps ssao samples";
  }
  // Timing intervals around the medians; both scores named.
  for (const char* h : {"reps", "total_lo_ms", "total_hi_ms", "interval_coverage", "declared",
                        "declared_nrmse", "declared_ssim"})
    EXPECT_NE(std::find(header.begin(), header.end(), h), header.end()) << h;

  // JSON: the same rows, finite metrics, the floor pass measured.
  const nlohmann::json j = nlohmann::json::parse(readAll(out + "/results.json"));
  ASSERT_EQ(j["results"].size(), rows);
  for (const auto& row : j["results"]) {
    for (const char* k : {"nrmse", "ssim", "total_ms", "floor_ms", "total_over_floor"}) {
      ASSERT_TRUE(row[k].is_number()) << k << " " << row.dump();
      EXPECT_TRUE(std::isfinite(row[k].get<double>())) << k;
    }
    EXPECT_GT(row["floor_ms"].get<double>(), 0.0);
    EXPECT_GT(row["pixels"].get<size_t>(), 0u);
    EXPECT_LE(row["ssim"].get<double>(), 1.0 + 1e-9);
    EXPECT_EQ(row["reps"].get<int>(), 5);
    const auto& total = row["total_interval"];
    EXPECT_LE(total["lo"].get<double>(), row["total_ms"].get<double>());
    EXPECT_GE(total["hi"].get<double>(), row["total_ms"].get<double>());
    EXPECT_DOUBLE_EQ(total["coverage"].get<double>(), 1.0 - 2.0 / 32.0);  // 5 reps: [min, max]
    ASSERT_TRUE(row["declared_nrmse"].is_number());
    if (hasSsao()) {
      // SSAO declares obscurance with the linear membership; its target is AO.
      EXPECT_EQ(row["declared"].get<std::string>().rfind("obscurance linear r=0.5", 0), 0u)
          << row["declared"];
      EXPECT_EQ(row["reference"].get<std::string>().rfind("ao r=0.5", 0), 0u) << row["reference"];
      EXPECT_NE(row["declared_nrmse"].get<double>(), row["nrmse"].get<double>());
    }
  }
  // A rerun uses the cached reference and gives the same errors.
  auto again = test::runCommand(bench("--quick --cache '" + dir + "/cache' --out '" + out + "'"));
  ASSERT_EQ(again.exitCode, 0) << again.output;
  const nlohmann::json j2 = nlohmann::json::parse(readAll(out + "/results.json"));
  for (size_t i = 0; i < rows; ++i)
    EXPECT_DOUBLE_EQ(j2["results"][i]["nrmse"].get<double>(),
                     j["results"][i]["nrmse"].get<double>());
}

// The declared quantity's parameters come from the configuration's settings: another radius is
// another reference (its own cache entry) for both scores.
TEST(BenchCli, DeclaredQuantityFollowsTheSweptRadius) {
  if (!hasSsao()) GTEST_SKIP() << "the ssao plugin is not built";
  const std::string dir = test::makeTempDir("bench-declared");
  const std::string out = dir + "/out", cache = dir + "/cache";
  auto r =
      test::runCommand(bench("--quick --reps 2 --effects ssao --grid ssao.radius=0.3,0.6 "
                             "--cache '" +
                             cache + "' --out '" + out + "'"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const nlohmann::json j = nlohmann::json::parse(readAll(out + "/results.json"));
  ASSERT_EQ(j["results"].size(), 2u);
  EXPECT_EQ(j["results"][0]["declared"].get<std::string>().rfind("obscurance linear r=0.3", 0), 0u);
  EXPECT_EQ(j["results"][1]["declared"].get<std::string>().rfind("obscurance linear r=0.6", 0), 0u);
  EXPECT_EQ(j["results"][1]["reference"].get<std::string>().rfind("ao r=0.6", 0), 0u);
  EXPECT_NE(j["results"][0]["declared_nrmse"], j["results"][1]["declared_nrmse"]);
  // Obscurance is not AO: the error against AO is split into that gap and the estimator's.
  for (const auto& row : j["results"]) {
    ASSERT_TRUE(row.contains("quantity_gap")) << row.dump();
    EXPECT_GT(row["quantity_gap"]["gap_nrmse"].get<double>(), 0.0);
    EXPECT_TRUE(std::isfinite(row["quantity_gap"]["gap_share"].get<double>()));
  }
  EXPECT_NE(readAll(out + "/report.md").find("## The declared quantity against the target"),
            std::string::npos);
  size_t entries = 0;
  for (const auto& e : fs::directory_iterator(cache)) entries += e.path().extension() == ".json";
  EXPECT_EQ(entries, 4u) << "AO and obscurance(linear) at two radii";
}

// Several effects on one scene against the same target: one chart with every effect as a
// series (the methods side by side), before the per-effect charts, and one of each against
// the quantity it declares.
TEST(BenchCli, SeveralEffectsShareOneChartPerScene) {
  const bool hasGtao = fs::exists(test::binPath("plugins/gi_effect_gtao.so"));
  if (!hasSsao() || !hasGtao) GTEST_SKIP() << "the ssao and gtao plugins are not built";
  const std::string dir = test::makeTempDir("bench-all");
  const std::string out = dir + "/out";
  auto r = test::runCommand(bench("--quick --reps 2 --effects ssao,gtao --cache '" + dir +
                                  "/cache' --out '" + out + "'"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const std::string report = readAll(out + "/report.md");
  const size_t all = report.find("plots/default_all.png"), one = report.find("plots/default_ssao");
  ASSERT_NE(all, std::string::npos) << report;
  EXPECT_LT(all, one) << "the combined chart comes first";
  const std::string svg = readAll(out + "/plots/default_all.svg");
  EXPECT_NE(svg.find("ssao"), std::string::npos);
  EXPECT_NE(svg.find("gtao"), std::string::npos);
  EXPECT_GT(fs::file_size(out + "/plots/default_all.png"), 1000u);
  // SSAO declares linear obscurance, not the AO target: a second chart scores each effect
  // against its own quantity.
  EXPECT_NE(report.find("plots/default_all_declared.png"), std::string::npos) << report;
  const std::string declared = readAll(out + "/plots/default_all_declared.svg");
  EXPECT_NE(declared.find("declared quantity"), std::string::npos);
  EXPECT_NE(declared.find("ssao"), std::string::npos);
}

// repetitions.csv keeps every round of every configuration (median and fastest frame, and with
// --isolate-passes the process CPU time), and tools/bench-pairs pairs two configurations round
// by round: its matched-error ratio is the median of the per-round ratios of that file.
TEST(BenchCli, RepetitionsArePairedRoundByRound) {
  const bool hasGtao = fs::exists(test::binPath("plugins/gi_effect_gtao.so"));
  if (!hasSsao() || !hasGtao) GTEST_SKIP() << "the ssao and gtao plugins are not built";
  const std::string dir = test::makeTempDir("bench-reps");
  const std::string out = dir + "/out";
  auto r =
      test::runCommand(bench("--quick --reps 3 --isolate-passes --effects ssao,gtao --cache '" +
                             dir + "/cache' --out '" + out + "'"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  std::istringstream csv(readAll(out + "/repetitions.csv"));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line.rfind("scene,effect,preset,params,batch,rep,effect_ms,floor_ms,passes_ms,"
                       "effect_min_ms,passes_min_ms,effect_cpu_ms,passes_cpu_ms",
                       0),
            0u);
  std::map<std::string, std::vector<double>> cpu;  // per configuration, by round
  while (std::getline(csv, line)) {
    const std::vector<std::string> f = splitCsvLine(line);
    ASSERT_EQ(f.size(), 13u) << line;
    EXPECT_EQ(f[4], "0") << "one interleave batch";
    const std::string config = f[1] + " " + f[3];  // --quick sweeps ssao.samples=4,16
    EXPECT_EQ(std::stoi(f[5]), int(cpu[config].size())) << "rounds in order";
    const double median = std::stod(f[6]), fastest = std::stod(f[9]), cpuMs = std::stod(f[11]);
    EXPECT_LE(fastest, median + 1e-9) << line;
    EXPECT_TRUE(std::isfinite(cpuMs) && cpuMs > 0.0) << line;
    cpu[config].push_back(cpuMs);
  }
  // The report puts each pass's and the effect's CPU ms beside their GPU times.
  const std::string report = readAll(out + "/report.md");
  EXPECT_TRUE(
      std::regex_search(report, std::regex(R"(\| ssao [0-9.]+ \[[0-9., ]+\] \(CPU [0-9.]+\))")) ||
      std::regex_search(report, std::regex(R"(, ssao [0-9.]+ \[[0-9., ]+\] \(CPU [0-9.]+\))")))
      << "per pass";
  EXPECT_TRUE(std::regex_search(report, std::regex(R"(\] \(CPU [0-9.]+\) \|)"))) << "the effect's";
  const std::string ssao = "ssao ssao.samples=4", gtao = "gtao ";
  ASSERT_EQ(cpu[ssao].size(), 3u);
  ASSERT_EQ(cpu[gtao].size(), 3u);
  // GTAO is the more accurate one here, so it is the "fast" side that reaches SSAO's error.
  std::vector<double> ratios;
  for (size_t k = 0; k < 3; ++k) ratios.push_back(cpu[ssao][k] / cpu[gtao][k]);
  std::sort(ratios.begin(), ratios.end());
  auto pairs =
      test::runCommand("python3 '" + std::string(GI_SOURCE_DIR) + "/tools/bench-pairs' matched '" +
                       out + "' --slow ssao --fast gtao");
  ASSERT_EQ(pairs.exitCode, 0) << pairs.output;
  char expected[64];
  std::snprintf(expected, sizeof expected, "**%.2f** [%.2f, %.2f]", ratios[1], ratios[0],
                ratios[2]);
  const size_t row = pairs.output.find("| ssao ssao.samples=4 |");
  ASSERT_NE(row, std::string::npos) << pairs.output;
  const std::string rowText = pairs.output.substr(row, pairs.output.find('\n', row) - row);
  EXPECT_NE(rowText.find(expected), std::string::npos) << expected << "\n" << pairs.output;
}

// Several presets: the report gets the platform-profile table (a column per preset, the
// settings each preset gives the effect, its time and both errors).
TEST(BenchCli, PresetsFormAPlatformProfileTable) {
  if (!fs::exists(test::binPath("plugins/gi_effect_gtao.so")))
    GTEST_SKIP() << "the gtao plugin is not built";
  const std::string dir = test::makeTempDir("bench-profiles");
  const std::string out = dir + "/out";
  auto r = test::runCommand(bench("--quick --reps 2 --effects gtao --presets low,medium --cache '" +
                                  dir + "/cache' --out '" + out + "'"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const std::string report = readAll(out + "/report.md");
  const size_t table = report.find("## Platform profiles");
  ASSERT_NE(table, std::string::npos) << report;
  EXPECT_NE(report.find("| effect | | low | medium |", table), std::string::npos) << report;
  EXPECT_NE(
      report.find("| gtao | settings | blur_radius 2, downsample 2, interleave true, slices 1",
                  table),
      std::string::npos)
      << "the low preset's gtao settings (assets/presets/low.json)\n"
      << report;
  EXPECT_NE(report.find("| gtao | NRMSE vs declared |", table), std::string::npos);
}

// 'all': every registered effect, each alone; with a preset, only the effects it configures
// (its platform-profile column); 'none' keeps all of them.
TEST(BenchCli, AllMeansEveryEffectEachPresetConfigures) {
  const std::string dir = test::makeTempDir("bench-all");
  { std::ofstream(dir + "/gtao_only.json") << R"({"effects": {"gtao": {"slices": 1}}})"; }
  EffectRegistry registry;
  registry.scanDefaultLocations();
  if (!registry.has("gtao")) GTEST_SKIP() << "the gtao plugin is not built";
  auto r = test::runCommand("GI_PRESET_PATH='" + dir + "' " +
                            bench("--quick --reps 1 --effects all --presets gtao_only,none "
                                  "--cache '" +
                                  dir + "/cache' --out '" + dir + "/out'"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const nlohmann::json rows = nlohmann::json::parse(readAll(dir + "/out/results.json"))["results"];
  std::set<std::string> withPreset, withNone;
  for (const auto& row : rows)
    (row["preset"] == "gtao_only" ? withPreset : withNone).insert(row["effect"]);
  EXPECT_EQ(withPreset, std::set<std::string>{"gtao"});
  const std::vector<std::string> names = registry.names();
  EXPECT_EQ(withNone, std::set<std::string>(names.begin(), names.end()));
}

TEST(BenchCli, BadInputFailsBeforeRendering) {
  const std::string dir = test::makeTempDir("bench-bad");
  const std::string out = dir + "/out";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--scenes no_such_scene.json", "no_such_scene.json"},
      {"--effects no_such_effect", "no_such_effect"},
      {"--presets no_such_preset", "no_such_preset"},
      {"--effects none --grid nodot=1", "nodot"},
      {"--effects none --grid ssao.samples=4", "ssao"},
      {"--frames 0", "--frames"},
      {"--metric ssim", "--metric"},                                 // only with --calibrate
      {"--effects ssao,ssao", "--effects: 'ssao' is listed twice"},  // as gi-render refuses it
      {"--effects none,ssao+ssao", "'ssao' appears twice in 'ssao+ssao'"},
      {"--width 1.5", "--width: expects an integer in [1, 16384], got '1.5'"},
      {"--ref-seed 0x20", "which is hexadecimal"},
      {"--effects ssao+", "'ssao+' has an empty effect name"},
      {"--effects none,+ssao", "'+ssao' has an empty effect name"},
  };
  for (const auto& [args, needle] : cases) {
    auto r = test::runCommand(
        bench("--quick " + args + " --cache '" + dir + "/cache' --out '" + out + "'"));
    EXPECT_NE(r.exitCode, 0) << args << ": " << r.output;
    EXPECT_LT(r.exitCode, 128) << args << ": " << r.output;
    EXPECT_NE(r.output.find("error"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(needle), std::string::npos) << args << ": " << r.output;
    EXPECT_FALSE(fs::exists(out)) << args << ": output written";
    EXPECT_FALSE(fs::exists(dir + "/cache")) << args << ": references computed";
  }
  // The hard-case sweep's options: none dropped silently, all checked before any render.
  const std::vector<std::pair<std::string, std::string>> hard = {
      {"--cases ''", "--cases: no case given"},
      {"--effects none --set ssao.radius=1", "'ssao' is neither 'engine' nor an effect of the"},
      {"--set nosuch.radius=1", "'nosuch' is neither 'engine' nor an effect of the sweep"},
      {"--effects none --set engine.no_such_key=1", "no_such_key"},
      {"--effects none --set engine.exposure=-1", "exposure"},
  };
  for (const auto& [args, needle] : hard) {
    auto r = test::runCommand(bench("--hard-cases " + args + " --out '" + out + "'"));
    EXPECT_NE(r.exitCode, 0) << args << ": " << r.output;
    EXPECT_LT(r.exitCode, 128) << args << ": " << r.output;
    EXPECT_NE(r.output.find(needle), std::string::npos) << args << ": " << r.output;
    EXPECT_FALSE(fs::exists(out)) << args << ": output written";
  }
  // A scene whose camera sees no geometry has nothing to score: an error naming it, not a
  // perfect NRMSE 0 / SSIM 1 over zero pixels.
  const std::string empty = dir + "/sees_nothing.json";
  std::ofstream(empty) << R"({ "models": [ { "primitive": "plane", "size": 1,
      "translation": [0, -100, 0] } ], "camera": { "position": [0, 0, 5], "target": [0, 0, 10] } })";
  auto nothing = test::runCommand(bench("--quick --no-progress --scenes '" + empty + "' --cache '" +
                                        dir + "/cache' --out '" + out + "'"));
  EXPECT_EQ(nothing.exitCode, 1) << nothing.output;
  EXPECT_NE(nothing.output.find(empty + ": no pixel is geometry in both"), std::string::npos)
      << nothing.output;
  EXPECT_FALSE(fs::exists(out));
  fs::remove_all(dir + "/cache");
  // An output folder that cannot be written is found before the sweep, not after it.
  for (const char* bad : {"/sys/gi-bench-out", "/sys"}) {
    auto r =
        test::runCommand(bench(std::string("--quick --cache '") + dir + "/cache' --out " + bad));
    EXPECT_EQ(r.exitCode, 1) << bad << ": " << r.output;
    EXPECT_NE(r.output.find("cannot write in the output folder /sys"), std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(dir + "/cache")) << bad << ": references computed";
  }
  // A FIFO where a result file goes, or in plots/: refused before the sweep, nothing written
  // beside it, the FIFO kept.
  for (const char* file : {"results.csv", "report.md", "plots/default_ssao.png"}) {
    const std::string full = out + "/" + file;
    fs::create_directories(fs::path(full).parent_path());
    ASSERT_EQ(::mkfifo(full.c_str(), 0600), 0) << full;
    auto r = test::runCommand(bench("--quick --cache '" + dir + "/cache' --out '" + out + "'"));
    EXPECT_EQ(r.exitCode, 1) << file << ": " << r.output;
    EXPECT_NE(r.output.find(full + ": output path is not a regular file"), std::string::npos)
        << r.output;
    EXPECT_TRUE(fs::is_fifo(full)) << file << ": replaced";
    EXPECT_FALSE(fs::exists(dir + "/cache")) << file << ": references computed";
    EXPECT_FALSE(fs::exists(out + "/results.json")) << file << ": results written";
    fs::remove_all(out);
  }
  if (hasSsao()) {
    for (const char* grid : {"ssao.no_such_key=1", "ssao.samples=100000", "ssao.samples=abc"}) {
      auto r = test::runCommand(bench(std::string("--quick --grid ") + grid + " --cache '" + dir +
                                      "/cache' --out '" + out + "'"));
      EXPECT_NE(r.exitCode, 0) << grid << ": " << r.output;
      EXPECT_LT(r.exitCode, 128) << r.output;
      EXPECT_FALSE(fs::exists(out)) << grid;
      EXPECT_FALSE(fs::exists(dir + "/cache")) << grid;
    }
  }
}

TEST(BenchCli, CalibratedPresetLoadsAndFitsTheBudget) {
  if (!hasSsao()) GTEST_SKIP() << "the ssao plugin is not built";
  const std::string dir = test::makeTempDir("bench-calibrate");
  const std::string preset = dir + "/calibrated.json";
  const double budget = 400.0;
  const bool alchemy = fs::exists(test::binPath("plugins/gi_effect_alchemy.so"));
  auto r = test::runCommand(bench("--calibrate --budget-ms " + std::to_string(budget) +
                                  " --width 64 --height 48 --frames 3 --ref-spp 16 --effects " +
                                  (alchemy ? "ssao,alchemy" : "ssao") + " --cache '" + dir +
                                  "/cache' --out '" + preset + "'"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const nlohmann::json j = nlohmann::json::parse(readAll(preset));
  ASSERT_TRUE(j["effects"]["ssao"]["samples"].is_number_integer()) << j.dump();
  EXPECT_EQ(j["target_ms"].get<double>(), budget);
  EXPECT_EQ(j["reference_resolution"], nlohmann::json({64, 48}));
  // The search is in the file: each effect calibrated alone, every power of two of its sample
  // counts (ssao: 1..64, alchemy: 1..64) with time, interval and scores, and the choice.
  const nlohmann::json& items = j["calibration"]["items"];
  ASSERT_EQ(items.size(), alchemy ? 2u : 1u) << j.dump(2);
  for (const auto& item : items) {
    EXPECT_EQ(item["candidates"].size(), 7u) << item.dump(2);
    const std::string e = item["effects"];
    EXPECT_EQ(item["chosen"],
              e + ".samples=" + std::to_string(j["effects"][e]["samples"].get<int>()));
    EXPECT_GE(item["margin_ms"].get<double>(), 0.0);
    for (const auto& c : item["candidates"])
      EXPECT_LE(c["interval_ms"][0].get<double>(), c["median_ms"].get<double>()) << c.dump();
  }

  // gi-render loads it; the chosen configuration's measured frame time is within the budget.
  auto g = test::runCommand(
      test::binPath("gi-render") + " --validation --scene default --effects ssao --preset '" +
      preset + "' --width 64 --height 48 --frames 3 --timings --out '" + dir + "/img.png'");
  ASSERT_EQ(g.exitCode, 0) << g.output;
  const size_t at = g.output.find("\ntotal");
  ASSERT_NE(at, std::string::npos) << g.output;
  const double total = std::stod(g.output.substr(at + 6));
  EXPECT_GT(total, 0.0);
  EXPECT_LE(total, budget) << g.output;

  // An impossible budget fails and writes nothing.
  const std::string none = dir + "/none.json";
  auto bad = test::runCommand(
      bench("--calibrate --budget-ms 0.000001 --width 64 --height 48 --frames 1 --ref-spp 4 "
            "--effects ssao --cache '" +
            dir + "/cache-none' --out '" + none + "'"));
  EXPECT_NE(bad.exitCode, 0) << bad.output;
  EXPECT_NE(bad.output.find("budget"), std::string::npos) << bad.output;
  // ... at once: only the cheapest configuration measured, no reference rendered.
  EXPECT_NE(bad.output.find("ssao at its cheapest (ssao.samples=1"), std::string::npos)
      << bad.output;
  EXPECT_NE(bad.output.find("stopped before the search"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(dir + "/cache-none") && !fs::is_empty(dir + "/cache-none")) << bad.output;
  EXPECT_FALSE(fs::exists(none));
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().string().find(".check"), std::string::npos) << e.path();
}

}  // namespace
}  // namespace gi
