// gi-render end to end: the default scene renders deterministically; every broken input exits
// non-zero with a message naming the file, and leaves no output file behind.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include "gi/image_io.h"
#include "process.h"
#include "test_support.h"

namespace gi {
namespace {

namespace fs = std::filesystem;

std::string render(const std::string& scene, const std::string& out,
                   const std::string& extra = "") {
  return test::binPath("gi-render") + " --validation --width 160 --height 120 --scene '" + scene +
         "' --out '" + out + "' " + extra;
}

TEST(Cli, DefaultSceneRendersDeterministically) {
  const std::string dir = test::makeTempDir("cli-default");
  auto a = test::runCommand(render("default", dir + "/a.png", "--frames 2 --timings"));
  ASSERT_EQ(a.exitCode, 0) << a.output;
  auto b = test::runCommand(render("default", dir + "/b.png"));
  ASSERT_EQ(b.exitCode, 0) << b.output;
  EXPECT_EQ(a.output.find("validation"), std::string::npos) << a.output;
  for (const char* pass : {"gbuffer", "lighting", "tonemap", "floor"})
    EXPECT_NE(a.output.find(pass), std::string::npos) << "timing table lacks " << pass << "\n"
                                                      << a.output;
  ImageRGBA8 ia = readPng(dir + "/a.png"), ib = readPng(dir + "/b.png");
  ASSERT_EQ(ia.width, 160);
  ASSERT_EQ(ia.height, 120);
  EXPECT_EQ(ia.pixels, ib.pixels) << "lavapipe renders deterministically; two runs must match";
  // Not a blank image: many distinct colours (walls, boxes, sphere, sky).
  std::set<uint32_t> colours;
  for (size_t i = 0; i < ia.pixels.size(); i += 4)
    colours.insert(ia.pixels[i] | ia.pixels[i + 1] << 8 | ia.pixels[i + 2] << 16);
  EXPECT_GT(colours.size(), 200u);
}

TEST(Cli, HdrOutputIsFinite) {
  const std::string dir = test::makeTempDir("cli-pfm");
  auto r = test::runCommand(render("default", dir + "/lit.pfm"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  ImageRGBA32F img = readPfm(dir + "/lit.pfm");
  for (float v : img.pixels) ASSERT_TRUE(std::isfinite(v));
}

struct BadInput {
  std::string name, path;
};

class CliBadInput : public ::testing::TestWithParam<BadInput> {};

TEST_P(CliBadInput, FailsCleanlyWithoutOutput) {
  const std::string dir = test::makeTempDir("cli-bad-" + GetParam().name);
  const std::string out = dir + "/out.png";
  auto r = test::runCommand(render(GetParam().path, out));
  EXPECT_NE(r.exitCode, 0) << r.output;
  EXPECT_LT(r.exitCode, 128) << "crashed (signal): " << r.output;
  EXPECT_NE(r.output.find("error"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(fs::path(GetParam().path).filename().string()), std::string::npos)
      << "message must name the file: " << r.output;
  EXPECT_FALSE(fs::exists(out)) << "partial output left behind";
  EXPECT_TRUE(fs::is_empty(dir)) << "temporary files left behind";
}

std::vector<BadInput> badInputs() {
  const std::string dir = test::makeTempDir("cli-bad-inputs");
  std::ofstream(dir + "/empty.gltf");
  std::ofstream(dir + "/empty.json");
  std::ofstream(dir + "/garbage.glb") << "this is not a glTF binary";
  std::ofstream(dir + "/unknown_key.json") << R"({"camera": {"position": [0,0,5]}, "colour": 1})";
  std::ofstream(dir + "/missing_model.json") << R"({"models": [{"file": "no-such-model.gltf"}]})";
  std::ofstream(dir + "/model.xyz") << "1 2 3";
  const std::string g = test::assimpModel("glTF2/");
  return {
      {"missing", dir + "/does-not-exist.gltf"},
      {"empty_gltf", dir + "/empty.gltf"},
      {"empty_json", dir + "/empty.json"},
      {"garbage", dir + "/garbage.glb"},
      {"unknown_key", dir + "/unknown_key.json"},
      {"missing_model", dir + "/missing_model.json"},
      {"unsupported_ext", dir + "/model.xyz"},
      {"index_out_of_range", g + "IndexOutOfRange/IndexOutOfRange.gltf"},
      {"missing_bin", g + "MissingBin/BoxTextured.gltf"},
      {"recursive_nodes", g + "RecursiveNodes/RecursiveNodes.gltf"},
      {"incorrect_vertex_arrays", g + "IncorrectVertexArrays/Cube.gltf"},
      {"wrong_types", g + "wrongTypes/badArray.gltf"},
      {"schema_failure", g + "SchemaFailures/sceneWrongType.gltf"},
  };
}

INSTANTIATE_TEST_SUITE_P(Broken, CliBadInput, ::testing::ValuesIn(badInputs()),
                         [](const auto& info) { return info.param.name; });

TEST(Cli, BadNormalsAreRepairedNotNaN) {
  const std::string dir = test::makeTempDir("cli-badnormals");
  const std::string model = test::assimpModel("glTF2/BoxBadNormals-glTF-Binary/BoxBadNormals.glb");
  auto r = test::runCommand(render(model, dir + "/n.pfm", "--view normal"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  ImageRGBA32F img = readPfm(dir + "/n.pfm");
  size_t geometry = 0;
  for (size_t i = 0; i < img.pixels.size(); i += 4) {
    for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(img.pixels[i + c]));
    float len = std::sqrt(img.pixels[i] * img.pixels[i] + img.pixels[i + 1] * img.pixels[i + 1] +
                          img.pixels[i + 2] * img.pixels[i + 2]);
    if (len > 0.0f) {
      ++geometry;
      EXPECT_NEAR(len, 1.0f, 2e-3f);
    }
  }
  EXPECT_GT(geometry, 100u);
}

TEST(Cli, InfinitePositionsNeverRenderNaN) {
  const std::string dir = test::makeTempDir("cli-infinites");
  const std::string model =
      test::assimpModel("glTF2/BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb");
  auto r = test::runCommand(render(model, dir + "/lit.pfm"));
  if (r.exitCode != 0) {  // rejected: then with a clear message and no output
    EXPECT_NE(r.output.find("BoxWithInfinites"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(dir + "/lit.pfm"));
    return;
  }
  ImageRGBA32F img = readPfm(dir + "/lit.pfm");
  for (float v : img.pixels) ASSERT_TRUE(std::isfinite(v));
}

// The points view with --surface-points, timed per isolated pass: the pass table lists the
// point passes, the image shows points, and without a reader the pass is reported culled.
TEST(Cli, SurfacePointsViewAndIsolatedTimings) {
  const std::string dir = test::makeTempDir("cli-points");
  auto r =
      test::runCommand(render("default", dir + "/points.png",
                              "--surface-points 80000 --view points --isolate-passes --timings"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  for (const char* line : {"surface_points", "points_view", "surface points: 80000\n"})
    EXPECT_NE(r.output.find(line), std::string::npos) << line << "\n" << r.output;
  const ImageRGBA8 img = readPng(dir + "/points.png");
  size_t lit = 0;
  for (size_t i = 0; i < img.pixels.size(); i += 4)
    lit += img.pixels[i] + img.pixels[i + 1] + img.pixels[i + 2] > 0;
  EXPECT_GT(lit, img.pixels.size() / 4 / 4) << "few points visible";
  r = test::runCommand(render("default", dir + "/plain.png", "--surface-points 20000 --timings"));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("pass culled"), std::string::npos) << r.output;
  r = test::runCommand(render("default", dir + "/bad.png", "--surface-points -1"));
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_FALSE(fs::exists(dir + "/bad.png"));
}

TEST(Cli, UsageErrors) {
  auto r = test::runCommand(test::binPath("gi-render") + " --scene default");
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_NE(r.output.find("--out"), std::string::npos);
  r = test::runCommand(test::binPath("gi-render") + " --scene default --out x.png --width -3");
  EXPECT_EQ(r.exitCode, 2) << r.output;
  r = test::runCommand(test::binPath("gi-render") + " --scene default --out x.png --bogus");
  EXPECT_EQ(r.exitCode, 2) << r.output;
  EXPECT_NE(r.output.find("--bogus"), std::string::npos);
}

// Numbers, lists and outputs follow apps/common/cli.h (test_cli_args tests it in detail); here
// the app itself: each ends with exit 2 (usage) or 1 and one line naming the flag or file, and
// an output that cannot be written is found before anything is rendered.
TEST(Cli, StrictNumbersListsAndOutputsBeforeRendering) {
  const std::string dir = test::makeTempDir("cli-strict");
  const std::string out = dir + "/x.png";
  struct Case {
    std::string args, mention;
    int exitCode;
  };
  ::mkfifo((dir + "/fifo.json").c_str(), 0600);
  fs::create_directories(dir + "/presetdir");
  const std::vector<Case> cases = {
      {"--width 1.5", "--width: expects an integer in [1, 16384], got '1.5'", 2},
      {"--width 0x20", "which is hexadecimal", 2},
      {"--height 12abc", "--height: expects an integer", 2},
      {"--time 1e400", "which is out of range (beyond +-1.8e308", 2},
      {"--exposure inf", "which is not a finite number", 2},
      {"--effects ssao,ssao", "--effects: 'ssao' is listed twice", 2},
      {"--scene '" + dir + "/fifo.json'", "fifo.json: is not a regular file", 1},
      {"--preset '" + dir + "/presetdir'", "presetdir: is a directory, not a preset file", 1},
  };
  for (const Case& c : cases) {
    auto r = test::runCommand(render("default", out, c.args));
    EXPECT_EQ(r.exitCode, c.exitCode) << c.args << "\n" << r.output;
    EXPECT_NE(r.output.find(c.mention), std::string::npos) << c.args << "\n" << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_FALSE(fs::exists(out)) << c.args;
  }
  // /sys exists and cannot be written (also as root): refused before the Vulkan device starts,
  // so no validation layer or device line is printed and it ends at once.
  for (const char* bad : {"/sys/gi-test.png", "--graph-dot /sys/gi-test.dot"}) {
    const std::string args = bad[0] == '-' ? std::string(bad) : "";
    auto r = test::runCommand(render("default", bad[0] == '-' ? out : bad, args));
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_NE(r.output.find("cannot write in the output folder /sys: "), std::string::npos)
        << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_FALSE(fs::exists(out));
  }
}

}  // namespace
}  // namespace gi
