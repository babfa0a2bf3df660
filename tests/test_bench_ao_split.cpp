// gi-bench --ao-split end to end: AO effects are compared with the ao-split reference; the report
// gains "Where screen-space AO cannot converge", the CSV and JSON the decomposition (finite,
// fractions in [0, 1], error shares summing to 1); the split reference is cached and a rerun
// reads it back; without the flag the outputs keep their former columns.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "bench_support.h"
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

TEST(BenchAoSplit, ReportsWhereScreenSpaceAoCannotConverge) {
  if (!fs::exists(test::binPath("plugins/gi_effect_ssao.so")))
    GTEST_SKIP() << "the ssao plugin is not built";
  const std::string dir = test::makeTempDir("bench-ao-split");
  const std::string out = dir + "/out", cache = dir + "/cache";
  auto r =
      test::runCommand(bench("--quick --ao-split --cache '" + cache + "' --out '" + out + "'"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const std::string report = readAll(out + "/report.md");
  EXPECT_NE(report.find("## Where screen-space AO cannot converge"), std::string::npos) << report;
  EXPECT_NE(report.find("share of MSE"), std::string::npos) << report;

  // CSV: the split columns, finite, on every (AO) row.
  std::istringstream csv(readAll(out + "/results.csv"));
  std::string line;
  std::getline(csv, line);
  const std::vector<std::string> header = splitCsvLine(line);
  std::map<std::string, size_t> col;
  for (size_t i = 0; i < header.size(); ++i) col[header[i]] = i;
  for (const char* k : {"reference_seconds", "limit_nrmse", "offscreen_nrmse", "hidden_nrmse",
                        "estimator_nrmse", "visible_fraction", "offscreen_fraction",
                        "hidden_fraction", "share_offscreen", "share_hidden", "share_estimator"})
    ASSERT_TRUE(col.count(k)) << k << " missing from " << line;
  size_t rows = 0;
  while (std::getline(csv, line)) {
    const std::vector<std::string> cells = splitCsvLine(line);
    ASSERT_EQ(cells.size(), header.size()) << line;
    auto num = [&](const char* k) { return std::stod(cells[col[k]]); };
    for (const char* k : {"limit_nrmse", "offscreen_nrmse", "hidden_nrmse", "estimator_nrmse"}) {
      EXPECT_TRUE(std::isfinite(num(k))) << k;
      EXPECT_GE(num(k), 0.0) << k;
    }
    for (const char* k : {"visible_fraction", "offscreen_fraction", "hidden_fraction"}) {
      EXPECT_GE(num(k), 0.0) << k;
      EXPECT_LE(num(k), 1.0) << k;
    }
    EXPECT_NEAR(num("share_offscreen") + num("share_hidden") + num("share_estimator"), 1.0, 1e-4)
        << line;
    EXPECT_GT(num("reference_seconds"), 0.0);
    ++rows;
  }
  EXPECT_GE(rows, 2u);

  // JSON: the same decomposition per row; the default room is all in the frame, so nothing is
  // off-screen there, and its blocks hide occluders.
  const nlohmann::json j = nlohmann::json::parse(readAll(out + "/results.json"));
  ASSERT_EQ(j["results"].size(), rows);
  for (const auto& row : j["results"]) {
    const auto& s = row["ao_split"];
    ASSERT_TRUE(s.is_object()) << row.dump();
    EXPECT_NEAR(s["share_offscreen"].get<double>() + s["share_hidden"].get<double>() +
                    s["share_estimator"].get<double>(),
                1.0, 1e-9);
    EXPECT_EQ(s["offscreen_fraction"].get<double>(), 0.0);
    EXPECT_GT(s["hidden_fraction"].get<double>(), 0.0);
    EXPECT_GT(s["limit_nrmse"].get<double>(), 0.0);
    EXPECT_LT(s["limit_nrmse"].get<double>(), row["nrmse"].get<double>() + 1.0);
  }
  size_t splitFiles = 0;
  for (const auto& e : fs::directory_iterator(cache))
    splitFiles += e.path().string().ends_with(".split.pfm");
  EXPECT_EQ(splitFiles, 1u) << "one split reference, cached";

  // A rerun reads the cached split reference and gives the same decomposition.
  auto again =
      test::runCommand(bench("--quick --ao-split --cache '" + cache + "' --out '" + out + "'"));
  ASSERT_EQ(again.exitCode, 0) << again.output;
  const nlohmann::json j2 = nlohmann::json::parse(readAll(out + "/results.json"));
  for (size_t i = 0; i < rows; ++i) {
    EXPECT_EQ(j2["results"][i]["ao_split"]["limit_nrmse"],
              j["results"][i]["ao_split"]["limit_nrmse"]);
    EXPECT_EQ(j2["results"][i]["reference_seconds"], j["results"][i]["reference_seconds"]);
  }

  // Without --ao-split: no section, no extra columns, no ao_split objects.
  const std::string plain = dir + "/plain";
  auto p = test::runCommand(bench("--quick --cache '" + cache + "' --out '" + plain + "'"));
  ASSERT_EQ(p.exitCode, 0) << p.output;
  EXPECT_EQ(readAll(plain + "/report.md").find("cannot converge"), std::string::npos);
  EXPECT_EQ(readAll(plain + "/results.csv").find("limit_nrmse"), std::string::npos);
  const nlohmann::json jp = nlohmann::json::parse(readAll(plain + "/results.json"));
  for (const auto& row : jp["results"]) EXPECT_FALSE(row.contains("ao_split"));
  // The AO compared is the same estimate with and without the split.
  for (size_t i = 0; i < rows; ++i) EXPECT_EQ(jp["results"][i]["nrmse"], j2["results"][i]["nrmse"]);
}

}  // namespace
}  // namespace gi
