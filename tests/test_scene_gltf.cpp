// glTF loader tests: broken files (assimp's test models and small files written here) fail with
// the right ErrorKind and a message naming the file; real models load with the right geometry;
// hierarchy, camera, light, material and accessor handling on hand-written files.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "gi/errors.h"
#include "gi/scene_io.h"
#include "test_support.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// ---------------------------------------------------------------------------------------------
// Helpers

// Loads `path` expecting gi::Error of `kind` whose message names the file; returns the message.
std::string expectError(const std::string& path, gi::ErrorKind kind) {
  SCOPED_TRACE(path);
  try {
    gi::Scene scene = gi::loadGltf(path);
    ADD_FAILURE() << "loaded " << scene.triangleCount() << " triangles, expected an error of kind '"
                  << gi::errorKindName(kind) << "'";
  } catch (const gi::Error& e) {
    EXPECT_STREQ(gi::errorKindName(e.kind()), gi::errorKindName(kind)) << e.what();
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find(fs::path(path).filename().string()), std::string::npos)
        << e.what();
    return e.what();
  }
  return {};
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The JSON of a .gltf, or of a .glb's JSON chunk (header 12 bytes, chunk header 8).
json readGltfJson(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() >= 20 && std::memcmp(bytes.data(), "glTF", 4) == 0) {
    uint32_t length = 0;
    std::memcpy(&length, bytes.data() + 12, 4);
    return json::parse(bytes.begin() + 20, bytes.begin() + 20 + length);
  }
  return json::parse(bytes.begin(), bytes.end());
}

// Triangles the file declares, counted from the JSON alone (each mesh once, every primitive a
// triangle list here): index count / 3, or vertex count / 3 without indices.
size_t declaredTriangles(const json& doc) {
  size_t triangles = 0;
  for (const json& mesh : doc["meshes"])
    for (const json& prim : mesh["primitives"]) {
      EXPECT_EQ(prim.value("mode", 4), 4);
      const json& counted = prim.contains("indices")
                                ? doc["accessors"][prim["indices"].get<size_t>()]
                                : doc["accessors"][prim["attributes"]["POSITION"].get<size_t>()];
      triangles += counted["count"].get<size_t>() / 3;
    }
  return triangles;
}

// Every position finite, every normal finite and unit length, areas and indices consistent.
void expectSaneGeometry(const gi::Scene& scene) {
  for (const gi::Mesh& mesh : scene.meshes) {
    SCOPED_TRACE(mesh.name);
    ASSERT_EQ(mesh.indices.size() % 3, 0u);
    EXPECT_EQ(mesh.triangleAreas.size(), mesh.triangleCount());
    EXPECT_LT(mesh.material, scene.materials.size());
    for (uint32_t i : mesh.indices) ASSERT_LT(i, mesh.vertices.size());
    for (const gi::Vertex& v : mesh.vertices) {
      ASSERT_TRUE(std::isfinite(v.position.x) && std::isfinite(v.position.y) &&
                  std::isfinite(v.position.z));
      ASSERT_TRUE(std::isfinite(v.normal.x) && std::isfinite(v.normal.y) &&
                  std::isfinite(v.normal.z));
      ASSERT_NEAR(glm::length(v.normal), 1.0f, 1e-4f);
    }
  }
}

// world == parent.world * local for every node (and == local at the roots).
void expectWorldTransformsCompose(const gi::Scene& scene) {
  for (size_t n = 0; n < scene.nodes.size(); ++n) {
    const gi::Node& node = scene.nodes[n];
    const glm::mat4 expected =
        node.parent < 0 ? node.local : scene.nodes[node.parent].world * node.local;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        ASSERT_NEAR(node.world[c][r], expected[c][r], 1e-4f) << "node " << n << " " << node.name;
  }
}

void expectNear(const glm::vec3& a, const glm::vec3& b, float eps = 1e-5f) {
  EXPECT_NEAR(a.x, b.x, eps);
  EXPECT_NEAR(a.y, b.y, eps);
  EXPECT_NEAR(a.z, b.z, eps);
}

// A fresh directory per test under the system temp dir, removed afterwards.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() /
            ("gi_test_scene_gltf_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  std::string file(const std::string& name) const { return (path_ / name).string(); }
  std::string write(const std::string& name, const std::string& bytes) const {
    std::ofstream(file(name), std::ios::binary) << bytes;
    return file(name);
  }

 private:
  fs::path path_;
};

// Builds a small glTF: binary data goes to <name>.bin next to <name>.gltf.
class GltfBuilder {
 public:
  GltfBuilder() { doc = {{"asset", {{"version", "2.0"}}}}; }

  // Appends bytes (4-byte aligned) and a bufferView over them; returns the view's index.
  template <typename T>
  int view(const std::vector<T>& data, int byteStride = 0) {
    while (bin_.size() % 4) bin_.push_back(0);
    json v = {{"buffer", 0}, {"byteOffset", bin_.size()}, {"byteLength", data.size() * sizeof(T)}};
    if (byteStride) v["byteStride"] = byteStride;
    const auto* p = reinterpret_cast<const char*>(data.data());
    bin_.insert(bin_.end(), p, p + data.size() * sizeof(T));
    doc["bufferViews"].push_back(v);
    return static_cast<int>(doc["bufferViews"].size()) - 1;
  }
  int accessor(int bufferView, int componentType, size_t count, const std::string& type,
               size_t byteOffset = 0, bool normalized = false) {
    json a = {{"bufferView", bufferView},
              {"componentType", componentType},
              {"count", count},
              {"type", type},
              {"byteOffset", byteOffset}};
    if (normalized) a["normalized"] = true;
    doc["accessors"].push_back(a);
    return static_cast<int>(doc["accessors"].size()) - 1;
  }
  // A mesh with one primitive; returns the mesh index.
  int mesh(const json& primitive) {
    doc["meshes"].push_back({{"primitives", json::array({primitive})}});
    return static_cast<int>(doc["meshes"].size()) - 1;
  }
  int node(const json& n) {
    doc["nodes"].push_back(n);
    return static_cast<int>(doc["nodes"].size()) - 1;
  }
  // The usual test geometry: one triangle (float positions, u16 indices); returns the mesh.
  int triangle() {
    int pos = accessor(view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}), kFloat, 3, "VEC3");
    int idx = accessor(view(std::vector<uint16_t>{0, 1, 2}), kUShort, 3, "SCALAR");
    return mesh({{"attributes", {{"POSITION", pos}}}, {"indices", idx}});
  }

  std::string write(const TempDir& dir, const std::string& name = "test") {
    if (!bin_.empty()) doc["buffers"] = {{{"uri", name + ".bin"}, {"byteLength", bin_.size()}}};
    dir.write(name + ".bin", std::string(bin_.begin(), bin_.end()));
    return dir.write(name + ".gltf", doc.dump(2));
  }

  static constexpr int kUByte = 5121, kUShort = 5123, kUInt = 5125, kFloat = 5126;
  json doc;

 private:
  std::vector<char> bin_;
};

// ---------------------------------------------------------------------------------------------
// Broken files shipped with assimp's test models

TEST(GltfBroken, IndexOutOfRange) {
  // Index 255 in a box with 24 vertices.
  std::string msg = expectError(gi::test::assimpModel("glTF2/IndexOutOfRange/IndexOutOfRange.gltf"),
                                gi::ErrorKind::IndexOutOfRange);
  EXPECT_TRUE(contains(msg, "index 255")) << msg;
  EXPECT_TRUE(contains(msg, "accessor 0")) << msg;
}

TEST(GltfBroken, AllIndicesOutOfRange) {
  // Every index is 65535 with 24 vertices.
  std::string msg =
      expectError(gi::test::assimpModel("glTF2/IndexOutOfRange/AllIndicesOutOfRange.gltf"),
                  gi::ErrorKind::IndexOutOfRange);
  EXPECT_TRUE(contains(msg, "index 65535")) << msg;
}

TEST(GltfBroken, MissingBin) {
  // BoxTextured0.bin (and the texture) are absent from the folder.
  std::string msg = expectError(gi::test::assimpModel("glTF2/MissingBin/BoxTextured.gltf"),
                                gi::ErrorKind::MissingResource);
  EXPECT_TRUE(contains(msg, "BoxTextured0.bin")) << msg;
}

TEST(GltfBroken, BoxWithInfinites) {
  // Every vertex has an infinite x, so every triangle goes and nothing is left to render. A
  // loader that sanitised differently would have to leave only finite data.
  const std::string path =
      gi::test::assimpModel("glTF2/BoxWithInfinites-glTF-Binary/BoxWithInfinites.glb");
  try {
    gi::Scene scene = gi::loadGltf(path);
    expectSaneGeometry(scene);
    ADD_FAILURE() << "expected NonFinite: every triangle of this box has an infinite vertex";
  } catch (const gi::Error& e) {
    EXPECT_STREQ(gi::errorKindName(e.kind()), gi::errorKindName(gi::ErrorKind::NonFinite));
    EXPECT_TRUE(contains(e.what(), "BoxWithInfinites.glb")) << e.what();
  }
}

TEST(GltfBroken, WrongTypes) {
  // Each file is BoxTextured with one property of the wrong JSON type.
  const struct {
    const char* file;
    const char* where;  // JSON path the message must name
  } cases[] = {
      {"badArray.gltf", "meshes[0].primitives"},       // an object instead of an array
      {"badExtension.gltf", "KHR_texture_transform"},  // extension value is a string
      {"badNumber.gltf", "normalTexture"},             // "scale": "not a number" (and no index)
      {"badObject.gltf", "materials[0].pbrMetallicRoughness"},  // an array
      {"badString.gltf", "scenes[0].name"},                     // 42
      {"badUint.gltf", "baseColorTexture.index"},               // -1
  };
  for (const auto& c : cases) {
    std::string msg = expectError(gi::test::assimpModel(std::string("glTF2/wrongTypes/") + c.file),
                                  gi::ErrorKind::Schema);
    EXPECT_TRUE(contains(msg, c.where)) << msg;
  }
}

TEST(GltfBroken, RecursiveNodes) {
  // Node 0 is the child of node 1 and node 1 the child of node 0.
  std::string msg = expectError(gi::test::assimpModel("glTF2/RecursiveNodes/RecursiveNodes.gltf"),
                                gi::ErrorKind::Cycle);
  EXPECT_TRUE(contains(msg, "own ancestor")) << msg;
}

TEST(GltfBroken, IncorrectVertexArrays) {
  // Mesh 1 "TruncatedCube" is a non-indexed triangle list of 35 vertices (also: bufferViews
  // 2-4 reach past the 514-byte buffer, but no primitive uses them).
  std::string msg = expectError(gi::test::assimpModel("glTF2/IncorrectVertexArrays/Cube.gltf"),
                                gi::ErrorKind::InvalidData);
  EXPECT_TRUE(contains(msg, "TruncatedCube")) << msg;
  EXPECT_TRUE(contains(msg, "35 vertices")) << msg;
}

TEST(GltfBroken, BoxBadNormalsAreRepaired) {
  // Four normals are zero, four are (0, -0.1, 0): loads with every normal unit length.
  gi::Scene scene =
      gi::loadGltf(gi::test::assimpModel("glTF2/BoxBadNormals-glTF-Binary/BoxBadNormals.glb"));
  EXPECT_EQ(scene.triangleCount(), 12u);
  expectSaneGeometry(scene);
  EXPECT_FALSE(scene.warnings.empty());
  // The -0.1 normals belong to the -y face and keep their direction.
  const gi::Mesh& mesh = scene.meshes.at(0);
  bool sawMinusY = false;
  for (const gi::Vertex& v : mesh.vertices)
    if (v.position.y < -0.49f && std::abs(v.normal.y + 1.0f) < 1e-5f) sawMinusY = true;
  EXPECT_TRUE(sawMinusY);
}

TEST(GltfBroken, NoSceneDefaultSceneMissing) {
  // "scene": 0 but no scenes at all (and no geometry).
  std::string msg = expectError(gi::test::assimpModel("glTF2/TestNoRootNode/NoScene.gltf"),
                                gi::ErrorKind::IndexOutOfRange);
  EXPECT_TRUE(contains(msg, "default scene 0")) << msg;
}

TEST(GltfBroken, SceneWithoutNodes) {
  // One empty scene, no meshes.
  std::string msg =
      expectError(gi::test::assimpModel("glTF2/TestNoRootNode/SceneWithoutNodes.gltf"),
                  gi::ErrorKind::InvalidData);
  EXPECT_TRUE(contains(msg, "no geometry")) << msg;
}

TEST(GltfBroken, SceneWrongType) {
  // "scene": "hello" (its .bin is missing too, but the schema is checked first).
  std::string msg = expectError(gi::test::assimpModel("glTF2/SchemaFailures/sceneWrongType.gltf"),
                                gi::ErrorKind::Schema);
  EXPECT_TRUE(contains(msg, "scene")) << msg;
}

// ---------------------------------------------------------------------------------------------
// Broken files written here

TEST(GltfFiles, MissingFile) {
  TempDir dir;
  expectError(dir.file("does_not_exist.gltf"), gi::ErrorKind::FileNotFound);
}

TEST(GltfFiles, EmptyFile) {
  TempDir dir;
  expectError(dir.write("empty.gltf", ""), gi::ErrorKind::EmptyFile);
  expectError(dir.write("empty.glb", ""), gi::ErrorKind::EmptyFile);
}

TEST(GltfFiles, GarbageBytes) {
  TempDir dir;
  std::string garbage;
  for (int i = 0; i < 512; ++i) garbage.push_back(static_cast<char>((i * 7919 + 13) % 256));
  expectError(dir.write("garbage.gltf", garbage), gi::ErrorKind::Parse);
  expectError(dir.write("garbage.glb", garbage), gi::ErrorKind::Parse);
  expectError(dir.write("truncated.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": ["),
              gi::ErrorKind::Parse);
  // A GLB header (24 bytes in all) whose JSON chunk claims 255 bytes.
  const std::string glb("glTF\x02\0\0\0\x18\0\0\0\xff\0\0\0JSON{}  ", 24);
  expectError(dir.write("short.glb", glb), gi::ErrorKind::Parse);
}

TEST(GltfFiles, MissingAssetIsSchemaError) {
  TempDir dir;
  std::string msg =
      expectError(dir.write("noasset.gltf", "{\"nodes\": []}"), gi::ErrorKind::Schema);
  EXPECT_TRUE(contains(msg, "asset")) << msg;
}

TEST(GltfFiles, UnsupportedRequiredExtension) {
  TempDir dir;
  GltfBuilder b;
  b.node({{"mesh", b.triangle()}});
  b.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
  std::string msg = expectError(b.write(dir), gi::ErrorKind::Unsupported);
  EXPECT_TRUE(contains(msg, "KHR_draco_mesh_compression")) << msg;
}

TEST(GltfFiles, AccessorPastBufferView) {
  TempDir dir;
  GltfBuilder b;
  b.node({{"mesh", b.triangle()}});
  b.doc["accessors"][0]["byteOffset"] = 4;  // 3 VEC3 floats from byte 4 need 40 of 36 bytes
  std::string msg = expectError(b.write(dir), gi::ErrorKind::IndexOutOfRange);
  EXPECT_TRUE(contains(msg, "accessor 0")) << msg;
}

TEST(GltfFiles, BufferViewPastBuffer) {
  TempDir dir;
  GltfBuilder b;
  b.node({{"mesh", b.triangle()}});
  b.doc["bufferViews"][1]["byteLength"] = 600;
  std::string msg = expectError(b.write(dir), gi::ErrorKind::IndexOutOfRange);
  EXPECT_TRUE(contains(msg, "bufferView 1")) << msg;
}

TEST(GltfFiles, AccessorIndexOutOfRange) {
  TempDir dir;
  GltfBuilder b;
  b.node({{"mesh", b.triangle()}});
  b.doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 7;
  std::string msg = expectError(b.write(dir), gi::ErrorKind::IndexOutOfRange);
  EXPECT_TRUE(contains(msg, "accessor 7")) << msg;
}

TEST(GltfFiles, AttributeCountMismatch) {
  TempDir dir;
  GltfBuilder b;
  b.node({{"mesh", b.triangle()}});
  int normals =
      b.accessor(b.view(std::vector<float>{0, 0, 1, 0, 0, 1}), GltfBuilder::kFloat, 2, "VEC3");
  b.doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = normals;
  std::string msg = expectError(b.write(dir), gi::ErrorKind::InvalidData);
  EXPECT_TRUE(contains(msg, "NORMAL")) << msg;
}

TEST(GltfFiles, WrongAttributeFormat) {
  TempDir dir;
  GltfBuilder b;
  b.node({{"mesh", b.triangle()}});
  b.doc["accessors"][0]["type"] = "VEC2";
  std::string msg = expectError(b.write(dir), gi::ErrorKind::Schema);
  EXPECT_TRUE(contains(msg, "POSITION")) << msg;
  EXPECT_TRUE(contains(msg, "VEC3")) << msg;
}

TEST(GltfFiles, BadHierarchies) {
  TempDir dir;
  {
    GltfBuilder b;
    b.node({{"mesh", b.triangle()}, {"children", {3}}});
    expectError(b.write(dir, "child_out_of_range"), gi::ErrorKind::IndexOutOfRange);
  }
  {
    GltfBuilder b;
    b.node({{"mesh", b.triangle()}, {"children", {0}}});
    expectError(b.write(dir, "own_child"), gi::ErrorKind::Cycle);
  }
  {
    GltfBuilder b;
    int mesh = b.triangle();
    b.node({{"children", {2}}});
    b.node({{"children", {2}}});
    b.node({{"mesh", mesh}});
    std::string msg = expectError(b.write(dir, "two_parents"), gi::ErrorKind::Cycle);
    EXPECT_TRUE(contains(msg, "node 2")) << msg;
  }
  {
    GltfBuilder b;
    b.node({{"mesh", b.triangle()}});
    b.doc["scenes"] = {{{"nodes", {0, 0}}}};
    expectError(b.write(dir, "root_twice"), gi::ErrorKind::Cycle);
  }
  {
    GltfBuilder b;
    b.node({{"mesh", 4}});
    b.triangle();
    expectError(b.write(dir, "mesh_out_of_range"), gi::ErrorKind::IndexOutOfRange);
  }
  {
    GltfBuilder b;
    b.node({{"mesh", b.triangle()}, {"camera", 0}});
    expectError(b.write(dir, "camera_out_of_range"), gi::ErrorKind::IndexOutOfRange);
  }
}

TEST(GltfFiles, LinesOnlyIsNoGeometry) {
  TempDir dir;
  GltfBuilder b;
  b.node({{"mesh", b.triangle()}});
  b.doc["meshes"][0]["primitives"][0]["mode"] = 1;
  std::string msg = expectError(b.write(dir), gi::ErrorKind::InvalidData);
  EXPECT_TRUE(contains(msg, "no geometry")) << msg;
}

TEST(GltfFiles, MissingImage) {
  TempDir dir;
  GltfBuilder b;
  b.node({{"mesh", b.triangle()}});
  b.doc["meshes"][0]["primitives"][0]["material"] = 0;
  b.doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
  b.doc["textures"] = {{{"source", 0}}};
  b.doc["images"] = {{{"uri", "nowhere.png"}}};
  std::string msg = expectError(b.write(dir), gi::ErrorKind::MissingResource);
  EXPECT_TRUE(contains(msg, "nowhere.png")) << msg;
}

// ---------------------------------------------------------------------------------------------
// Real models

TEST(GltfModels, BoxTexturedVariants) {
  for (const char* rel :
       {"glTF2/BoxTextured-glTF/BoxTextured.gltf", "glTF2/BoxTextured-glTF-Binary/BoxTextured.glb",
        "glTF2/BoxTextured-glTF-Embedded/BoxTextured.gltf"}) {
    SCOPED_TRACE(rel);
    const std::string path = gi::test::assimpModel(rel);
    gi::Scene scene = gi::loadGltf(path);
    EXPECT_EQ(scene.triangleCount(), declaredTriangles(readGltfJson(path)));
    EXPECT_EQ(scene.triangleCount(), 12u);
    expectSaneGeometry(scene);
    ASSERT_EQ(scene.meshes.size(), 1u);
    const gi::Material& mat = scene.materials.at(scene.meshes[0].material);
    ASSERT_EQ(mat.baseColorTexture, 0);
    ASSERT_EQ(scene.textures.size(), 1u);
    const gi::Texture& tex = scene.textures[0];
    EXPECT_EQ(tex.width, 211);  // CesiumLogoFlat.png
    EXPECT_EQ(tex.height, 211);
    EXPECT_EQ(tex.rgba8.size(), size_t(tex.width) * size_t(tex.height) * 4);
    EXPECT_EQ(scene.sourcePath, path);
    expectWorldTransformsCompose(scene);
  }
}

TEST(GltfModels, TwoCylinderEngine) {
  const std::string path =
      gi::test::assimpModel("glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb");
  gi::Scene scene = gi::loadGltf(path);
  const json doc = readGltfJson(path);
  // The file declares 75730 triangles, 10419 of which are degenerate (mostly repeated indices:
  // 1912 of the 11140 in "body_2") and are dropped, each primitive reporting how many.
  EXPECT_EQ(declaredTriangles(doc), 75730u);
  EXPECT_EQ(scene.triangleCount(), 65311u);
  size_t reportedDropped = 0;
  for (const std::string& warning : scene.warnings) {  // "...: dropped N degenerate triangles"
    const size_t at = warning.find(": dropped ");
    if (at != std::string::npos && contains(warning, " degenerate triangles"))
      reportedDropped += std::stoul(warning.substr(at + 10));
  }
  EXPECT_EQ(scene.triangleCount() + reportedDropped, declaredTriangles(doc));
  EXPECT_EQ(scene.nodes.size(), doc["nodes"].size());
  expectSaneGeometry(scene);
  // A deep hierarchy: world transforms must compose down it.
  int depth = 0;
  for (const gi::Node& node : scene.nodes) {
    int d = 0;
    for (int p = node.parent; p >= 0; p = scene.nodes[p].parent) ++d;
    depth = std::max(depth, d);
  }
  EXPECT_GE(depth, 3);
  expectWorldTransformsCompose(scene);
}

TEST(GltfModels, Fox) {
  const std::string gltf = gi::test::modelAsset("fox/glTF/Fox.gltf");
  for (const std::string& file : {gltf, gi::test::modelAsset("fox/glTF-Binary/Fox.glb")}) {
    SCOPED_TRACE(file);
    gi::Scene scene = gi::loadGltf(file);  // skinned and animated: both are ignored
    EXPECT_EQ(scene.triangleCount(), declaredTriangles(readGltfJson(file)));
    EXPECT_EQ(scene.triangleCount(), 576u);
    expectSaneGeometry(scene);
    ASSERT_EQ(scene.textures.size(), 1u);
    EXPECT_EQ(scene.textures[0].width, 1024);
    expectWorldTransformsCompose(scene);
  }
}

TEST(GltfModels, CesiumMan) {
  const std::string gltf = gi::test::modelAsset("cesium_man/glTF/CesiumMan.gltf");
  for (const std::string& file :
       {gltf, gi::test::modelAsset("cesium_man/glTF-Binary/CesiumMan.glb")}) {
    SCOPED_TRACE(file);
    gi::Scene scene = gi::loadGltf(file);
    EXPECT_EQ(scene.triangleCount(), declaredTriangles(readGltfJson(file)));
    EXPECT_EQ(scene.triangleCount(), 4672u);
    expectSaneGeometry(scene);
    ASSERT_EQ(scene.textures.size(), 1u);
    EXPECT_EQ(scene.textures[0].width, 1024);  // CesiumMan_img0.jpg
    expectWorldTransformsCompose(scene);
  }
}

// ---------------------------------------------------------------------------------------------
// Features on hand-written files

TEST(GltfFeatures, HierarchyComposesWorldTransforms) {
  TempDir dir;
  GltfBuilder b;
  const int mesh = b.triangle();
  // root (translate 1,2,3) -> arm (rotate 90 deg about y, scale 2) -> hand (matrix: translate x 1)
  b.node({{"name", "root"}, {"translation", {1, 2, 3}}, {"children", {1}}});
  b.node({{"name", "arm"},
          {"rotation", {0, std::sin(glm::radians(45.0)), 0, std::cos(glm::radians(45.0))}},
          {"scale", {2, 2, 2}},
          {"children", {2}}});
  b.node({{"name", "hand"},
          {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 1, 0, 0, 1}},
          {"mesh", mesh}});
  b.doc["scenes"] = {{{"nodes", {0}}}};
  b.doc["scene"] = 0;
  gi::Scene scene = gi::loadGltf(b.write(dir));
  ASSERT_EQ(scene.nodes.size(), 3u);
  ASSERT_EQ(scene.roots, std::vector<int>{0});
  expectWorldTransformsCompose(scene);
  const gi::Node& hand = scene.nodes[2];
  EXPECT_EQ(hand.name, "hand");
  EXPECT_EQ(hand.parent, 1);
  ASSERT_EQ(hand.meshes.size(), 1u);
  // The hand's origin: x 1 -> scaled 2 -> rotated onto -z -> moved by (1,2,3).
  expectNear(glm::vec3(hand.world * glm::vec4(0, 0, 0, 1)), glm::vec3(1, 2, 1));
  const glm::mat4 expected = glm::translate(glm::mat4(1), glm::vec3(1, 2, 3)) *
                             glm::rotate(glm::mat4(1), glm::radians(90.0f), glm::vec3(0, 1, 0)) *
                             glm::scale(glm::mat4(1), glm::vec3(2)) *
                             glm::translate(glm::mat4(1), glm::vec3(1, 0, 0));
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) EXPECT_NEAR(hand.world[c][r], expected[c][r], 1e-5f);
}

TEST(GltfFeatures, CameraAndSpotLight) {
  TempDir dir;
  GltfBuilder b;
  b.node({{"mesh", b.triangle()}});
  b.node({{"name", "cam"}, {"camera", 0}, {"translation", {0, 1, 5}}});
  b.node({{"name", "lamp"}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  b.doc["cameras"] = {
      {{"type", "perspective"},
       {"perspective", {{"yfov", 0.7}, {"aspectRatio", 1.5}, {"znear", 0.1}, {"zfar", 50}}}}};
  b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  b.doc["extensions"] = {{"KHR_lights_punctual",
                          {{"lights",
                            {{{"type", "spot"},
                              {"name", "spotty"},
                              {"color", {1.0, 0.5, 0.25}},
                              {"intensity", 20},
                              {"range", 10},
                              {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.6}}}}}}}}};
  gi::Scene scene = gi::loadGltf(b.write(dir));  // no scenes: every parentless node is a root

  ASSERT_EQ(scene.nodes.size(), 3u);
  ASSERT_EQ(scene.cameras.size(), 1u);
  const gi::Camera& cam = scene.cameras[0];
  EXPECT_FLOAT_EQ(cam.yfov, 0.7f);
  EXPECT_FLOAT_EQ(cam.aspect, 1.5f);
  EXPECT_FLOAT_EQ(cam.znear, 0.1f);
  EXPECT_FLOAT_EQ(cam.zfar, 50.0f);
  ASSERT_EQ(scene.activeCameraNode, 1);
  EXPECT_EQ(scene.nodes[1].camera, 0);
  expectNear(glm::vec3(scene.nodes[1].world[3]), glm::vec3(0, 1, 5));

  ASSERT_EQ(scene.lights.size(), 1u);
  const gi::Light& light = scene.lights[0];
  EXPECT_EQ(light.name, "spotty");
  EXPECT_EQ(light.type, gi::LightType::Spot);
  expectNear(light.color, glm::vec3(1.0f, 0.5f, 0.25f));
  EXPECT_FLOAT_EQ(light.intensity, 20.0f);
  EXPECT_FLOAT_EQ(light.range, 10.0f);
  EXPECT_FLOAT_EQ(light.innerConeAngle, 0.2f);
  EXPECT_FLOAT_EQ(light.outerConeAngle, 0.6f);
  EXPECT_EQ(scene.nodes[2].light, 0);
}

TEST(GltfFeatures, OrthographicCameraAndOtherLightTypes) {
  TempDir dir;
  GltfBuilder b;
  b.node({{"mesh", b.triangle()}, {"camera", 0}});
  b.node({{"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}});
  b.doc["cameras"] = {{{"type", "orthographic"},
                       {"orthographic", {{"xmag", 2}, {"ymag", 2}, {"znear", 0.5}, {"zfar", 20}}}}};
  b.doc["extensions"] = {
      {"KHR_lights_punctual",
       {{"lights", {{{"type", "directional"}, {"intensity", 3}}, {{"type", "point"}}}}}}};
  gi::Scene scene = gi::loadGltf(b.write(dir));
  ASSERT_EQ(scene.cameras.size(), 1u);
  EXPECT_FLOAT_EQ(scene.cameras[0].znear, 0.5f);
  EXPECT_FLOAT_EQ(scene.cameras[0].zfar, 20.0f);
  EXPECT_TRUE(std::any_of(scene.warnings.begin(), scene.warnings.end(),
                          [](const std::string& w) { return contains(w, "orthographic"); }));
  ASSERT_EQ(scene.lights.size(), 2u);
  EXPECT_EQ(scene.lights[0].type, gi::LightType::Directional);
  EXPECT_FLOAT_EQ(scene.lights[0].intensity, 3.0f);
  EXPECT_EQ(scene.lights[1].type, gi::LightType::Point);
  expectNear(scene.lights[1].color, glm::vec3(1.0f));  // defaults
  EXPECT_FLOAT_EQ(scene.lights[1].intensity, 1.0f);
  EXPECT_FLOAT_EQ(scene.lights[1].range, 0.0f);
  EXPECT_EQ(scene.nodes[1].light, 1);
}

TEST(GltfFeatures, MaterialFactors) {
  TempDir dir;
  GltfBuilder b;
  b.node({{"mesh", b.triangle()}});
  b.node({{"mesh", b.triangle()}});
  b.doc["meshes"][0]["primitives"][0]["material"] = 0;
  b.doc["materials"] = {
      {{"name", "glow"},
       {"pbrMetallicRoughness",
        {{"baseColorFactor", {0.5, 0.25, 0.125, 1.0}},
         {"metallicFactor", 0.75},
         {"roughnessFactor", 0.3}}},
       {"emissiveFactor", {1.0, 0.5, 0.0}},
       {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4.0}}}}}}};
  gi::Scene scene = gi::loadGltf(b.write(dir));
  ASSERT_EQ(scene.meshes.size(), 2u);
  const gi::Material& glow = scene.materials.at(scene.meshes[0].material);
  EXPECT_EQ(glow.name, "glow");
  EXPECT_FLOAT_EQ(glow.baseColor.g, 0.25f);
  EXPECT_FLOAT_EQ(glow.metallic, 0.75f);
  EXPECT_FLOAT_EQ(glow.roughness, 0.3f);
  expectNear(glow.emission, glm::vec3(4.0f, 2.0f, 0.0f));
  EXPECT_EQ(glow.baseColorTexture, -1);
  // The second mesh has no material: it gets an added default one.
  EXPECT_NE(scene.meshes[1].material, scene.meshes[0].material);
  EXPECT_LT(scene.meshes[1].material, scene.materials.size());
}

TEST(GltfFeatures, StripsFansInterleavedAndNormalisedTexcoords) {
  TempDir dir;
  GltfBuilder b;
  // Interleaved vertices: position (3 floats) + u16 normalised uv (2 x u16) = 16 bytes.
  struct Packed {
    float p[3];
    uint16_t uv[2];
  };
  std::vector<Packed> verts = {{{0, 0, 0}, {0, 0}},
                               {{1, 0, 0}, {65535, 0}},
                               {{0, 1, 0}, {0, 65535}},
                               {{1, 1, 0}, {65535, 65535}}};
  const int v = b.view(verts, sizeof(Packed));
  const int pos = b.accessor(v, GltfBuilder::kFloat, 4, "VEC3");
  const int uv = b.accessor(v, GltfBuilder::kUShort, 4, "VEC2", 12, true);
  const int strip =
      b.accessor(b.view(std::vector<uint8_t>{0, 1, 2, 3}), GltfBuilder::kUByte, 4, "SCALAR");
  const int fan =
      b.accessor(b.view(std::vector<uint32_t>{0, 1, 3, 2}), GltfBuilder::kUInt, 4, "SCALAR");
  json attributes = {{"POSITION", pos}, {"TEXCOORD_0", uv}};
  b.node({{"mesh", b.mesh({{"attributes", attributes}, {"indices", strip}, {"mode", 5}})}});
  b.node({{"mesh", b.mesh({{"attributes", attributes}, {"indices", fan}, {"mode", 6}})}});
  gi::Scene scene = gi::loadGltf(b.write(dir));
  ASSERT_EQ(scene.meshes.size(), 2u);
  EXPECT_EQ(scene.meshes[0].triangleCount(), 2u);
  EXPECT_EQ(scene.meshes[1].triangleCount(), 2u);
  expectSaneGeometry(scene);  // normals were missing: computed
  for (const gi::Mesh& mesh : scene.meshes) {
    for (const gi::Vertex& vtx : mesh.vertices) {
      expectNear(vtx.normal, glm::vec3(0, 0, 1));  // both keep the counter-clockwise winding
      EXPECT_FLOAT_EQ(vtx.uv.x, vtx.position.x);   // normalised 0..65535 -> 0..1
      EXPECT_FLOAT_EQ(vtx.uv.y, vtx.position.y);
    }
  }
  EXPECT_FALSE(scene.warnings.empty());  // "no normals in the file"
}

TEST(GltfFeatures, SparseAccessor) {
  TempDir dir;
  GltfBuilder b;
  const int mesh = b.triangle();
  // Replace vertex 2 (0,1,0) by (0,0,1).
  const int indices = b.view(std::vector<uint16_t>{2, 0});  // padded to 4 bytes
  const int values = b.view(std::vector<float>{0, 0, 1});
  b.doc["accessors"][0]["sparse"] = {
      {"count", 1},
      {"indices", {{"bufferView", indices}, {"componentType", GltfBuilder::kUShort}}},
      {"values", {{"bufferView", values}}}};
  b.node({{"mesh", mesh}});
  gi::Scene scene = gi::loadGltf(b.write(dir));
  ASSERT_EQ(scene.meshes.size(), 1u);
  const gi::Mesh& m = scene.meshes[0];
  ASSERT_EQ(m.triangleCount(), 1u);
  expectNear(m.vertices[m.indices[2]].position, glm::vec3(0, 0, 1));
}

TEST(GltfFeatures, NonFinitePositionsDropOnlyAffectedTriangles) {
  TempDir dir;
  GltfBuilder b;
  const float inf = std::numeric_limits<float>::infinity();
  const int pos = b.accessor(b.view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0, inf, 1, 0}),
                             GltfBuilder::kFloat, 4, "VEC3");
  const int idx = b.accessor(b.view(std::vector<uint16_t>{0, 1, 2, 1, 3, 2}), GltfBuilder::kUShort,
                             6, "SCALAR");
  b.node({{"mesh", b.mesh({{"attributes", {{"POSITION", pos}}}, {"indices", idx}})}});
  gi::Scene scene = gi::loadGltf(b.write(dir));
  EXPECT_EQ(scene.triangleCount(), 1u);
  expectSaneGeometry(scene);
  EXPECT_TRUE(std::any_of(scene.warnings.begin(), scene.warnings.end(),
                          [](const std::string& w) { return contains(w, "non-finite"); }));
}

TEST(GltfFeatures, NoNodesInstancesEveryMesh) {
  TempDir dir;
  GltfBuilder b;
  b.triangle();
  b.triangle();
  gi::Scene scene = gi::loadGltf(b.write(dir));
  ASSERT_EQ(scene.nodes.size(), 2u);
  EXPECT_EQ(scene.roots.size(), 2u);
  EXPECT_EQ(scene.meshes.size(), 2u);
  for (const gi::Node& node : scene.nodes) EXPECT_EQ(node.meshes.size(), 1u);
  EXPECT_FALSE(scene.materials.empty());
}

TEST(GltfFeatures, MeshInstancesShareGeometry) {
  TempDir dir;
  GltfBuilder b;
  const int mesh = b.triangle();
  b.node({{"mesh", mesh}, {"translation", {-1, 0, 0}}});
  b.node({{"mesh", mesh}, {"translation", {1, 0, 0}}});
  gi::Scene scene = gi::loadGltf(b.write(dir));
  EXPECT_EQ(scene.meshes.size(), 1u);
  ASSERT_EQ(scene.nodes.size(), 2u);
  EXPECT_EQ(scene.nodes[0].meshes, scene.nodes[1].meshes);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// The value rules of a JSON scene hold for glTF too (issue 15): the same values are refused,
// each with "<file>: <where in the glTF>: <problem>".

// A one-triangle file with `edit` applied, expected to fail with InvalidData naming `where`.
void expectValueRule(const std::function<void(GltfBuilder&)>& edit, const std::string& where,
                     const std::string& problem) {
  TempDir dir;
  GltfBuilder b;
  b.node({{"mesh", b.triangle()}});
  edit(b);
  const std::string msg = expectError(b.write(dir), gi::ErrorKind::InvalidData);
  EXPECT_TRUE(contains(msg, ".gltf: " + where + ": " + problem)) << msg;
}

json perspective(double yfov, double znear, double zfar) {
  json p = {{"yfov", yfov}, {"znear", znear}};
  if (zfar != 0.0) p["zfar"] = zfar;
  return json::array({{{"type", "perspective"}, {"perspective", p}}});
}

void withLight(GltfBuilder& b, const json& light) {
  b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  b.doc["extensions"] = {{"KHR_lights_punctual", {{"lights", json::array({light})}}}};
  b.node({{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
}

TEST(GltfValueRules, CamerasLightsAndMaterialsAsInJsonScenes) {
  expectValueRule([](GltfBuilder& b) { b.doc["cameras"] = perspective(0.0, 0.1, 10); },
                  "cameras[0].perspective.yfov", "must be in (0, pi) radians, got 0");
  expectValueRule([](GltfBuilder& b) { b.doc["cameras"] = perspective(3.5, 0.1, 10); },
                  "cameras[0].perspective.yfov", "must be in (0, pi) radians, got 3.5");
  expectValueRule([](GltfBuilder& b) { b.doc["cameras"] = perspective(0.7, 0.0, 10); },
                  "cameras[0].perspective.znear", "must be positive, got 0");
  expectValueRule([](GltfBuilder& b) { b.doc["cameras"] = perspective(0.7, 1.0, 0.5); },
                  "cameras[0].perspective.zfar", "must be greater than znear (1), got 0.5");
  expectValueRule(
      [](GltfBuilder& b) {
        b.doc["cameras"] = {
            {{"type", "orthographic"},
             {"orthographic", {{"xmag", 1}, {"ymag", 1}, {"znear", 2}, {"zfar", 1}}}}};
      },
      "cameras[0].orthographic.zfar", "must be greater than znear (2), got 1");
  expectValueRule(
      [](GltfBuilder& b) {
        withLight(b, {{"type", "point"}, {"intensity", -5}});
      },
      "KHR_lights_punctual.lights[0].intensity", "must not be negative, got -5");
  expectValueRule(
      [](GltfBuilder& b) {
        withLight(b, {{"type", "point"}, {"range", -1}});
      },
      "KHR_lights_punctual.lights[0].range", "must not be negative, got -1");
  expectValueRule(
      [](GltfBuilder& b) {
        withLight(b, {{"type", "point"}, {"color", {1, -0.5, 1}}});
      },
      "KHR_lights_punctual.lights[0].color", "colour components must not be negative");
  expectValueRule(
      [](GltfBuilder& b) {
        withLight(b,
                  {{"type", "spot"}, {"spot", {{"innerConeAngle", 0.8}, {"outerConeAngle", 0.5}}}});
      },
      "KHR_lights_punctual.lights[0].spot.innerConeAngle",
      "must be in [0, outerConeAngle] (0.5), got 0.8");
  expectValueRule(
      [](GltfBuilder& b) {
        withLight(b, {{"type", "spot"}, {"spot", {{"outerConeAngle", 2.0}}}});
      },
      "KHR_lights_punctual.lights[0].spot.outerConeAngle", "must be in (0, pi/2] radians, got 2");
  expectValueRule(
      [](GltfBuilder& b) {
        b.doc["materials"] = {{{"emissiveFactor", {-1, 0, 0}}}};
        b.doc["meshes"][0]["primitives"][0]["material"] = 0;
      },
      "materials[0].emissiveFactor", "colour components must not be negative");
  expectValueRule(
      [](GltfBuilder& b) {
        b.doc["materials"] = {
            {{"emissiveFactor", {1, 1, 1}},
             {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", -2}}}}}}};
        b.doc["extensionsUsed"] = {"KHR_materials_emissive_strength"};
      },
      "materials[0].extensions.KHR_materials_emissive_strength.emissiveStrength",
      "must not be negative, got -2");
  expectValueRule(
      [](GltfBuilder& b) {
        b.doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, -1, 1}}}}}};
      },
      "materials[0].pbrMetallicRoughness.baseColorFactor",
      "colour components must not be negative");
}

TEST(GltfValueRules, BoundaryValuesStillLoad) {
  TempDir dir;
  GltfBuilder b;
  b.node({{"mesh", b.triangle()}});
  b.doc["cameras"] = perspective(0.7, 0.1, 0);  // no zfar: infinite projection, allowed
  withLight(b, {{"type", "spot"},
                {"intensity", 0},
                {"spot", {{"innerConeAngle", 0.5}, {"outerConeAngle", 0.5}}}});
  const gi::Scene scene = gi::loadGltf(b.write(dir));
  ASSERT_EQ(scene.lights.size(), 1u);
  EXPECT_FLOAT_EQ(scene.lights[0].innerConeAngle, 0.5f);
  EXPECT_FLOAT_EQ(scene.lights[0].intensity, 0.0f);
  ASSERT_EQ(scene.cameras.size(), 1u);
  EXPECT_GT(scene.cameras[0].zfar, scene.cameras[0].znear);
}

TEST(GltfFiles, Version1IsNamedAsUnsupported) {
  TempDir dir;
  for (const char* text :
       {R"({"asset": {"version": "1.0"}, "scene": "defaultScene", "scenes": {}})",
        R"({"scene": "defaultScene", "meshes": {}, "nodes": {}})"}) {
    const std::string msg = expectError(dir.write("v1.gltf", text), gi::ErrorKind::Unsupported);
    EXPECT_TRUE(contains(msg, "glTF 1.0 is not supported")) << msg;
  }
  // Binary glTF 1: magic, version 1, length, content length, content format 0 (JSON).
  std::string glb("glTF\x01\0\0\0\x20\0\0\0\x0c\0\0\0\0\0\0\0{\"scene\":1}\n", 32);
  const std::string msg = expectError(dir.write("v1.glb", glb), gi::ErrorKind::Unsupported);
  EXPECT_TRUE(contains(msg, "glTF 1.0 is not supported")) << msg;
  expectError(dir.write("v3.gltf", R"({"asset": {"version": "3.0"}})"), gi::ErrorKind::Unsupported);
}

TEST(GltfFiles, BufferOrImageUriThatIsNotAFileIsNamed) {
  TempDir dir;
  fs::create_directories(dir.file("folder"));
  {
    GltfBuilder b;
    b.node({{"mesh", b.triangle()}});
    const std::string path = b.write(dir);
    json doc = readGltfJson(path);
    doc["buffers"][0]["uri"] = "folder";
    const std::string msg =
        expectError(dir.write("dirbuf.gltf", doc.dump()), gi::ErrorKind::MissingResource);
    EXPECT_TRUE(contains(msg, "is a directory")) << msg;
    EXPECT_FALSE(contains(msg, "bad_alloc")) << msg;
    ASSERT_EQ(::mkfifo(dir.file("fifo.bin").c_str(), 0600), 0);
    doc["buffers"][0]["uri"] = "fifo.bin";  // read until a writer comes, before: forever
    const std::string fifo =
        expectError(dir.write("fifobuf.gltf", doc.dump()), gi::ErrorKind::MissingResource);
    EXPECT_TRUE(contains(fifo, "not a regular file")) << fifo;
  }
  {
    GltfBuilder b;
    int pos = b.accessor(b.view(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}), GltfBuilder::kFloat,
                         3, "VEC3");
    int uv =
        b.accessor(b.view(std::vector<float>{0, 0, 1, 0, 0, 1}), GltfBuilder::kFloat, 3, "VEC2");
    b.mesh({{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv}}}, {"material", 0}});
    b.node({{"mesh", 0}});
    b.doc["images"] = {{{"uri", "folder"}}};
    b.doc["textures"] = {{{"source", 0}}};
    b.doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}};
    const std::string msg = expectError(b.write(dir, "dirimg"), gi::ErrorKind::MissingResource);
    EXPECT_TRUE(contains(msg, "image 0 ('folder')")) << msg;
    EXPECT_TRUE(contains(msg, "is a directory")) << msg;
  }
}

TEST(GltfFiles, DevicesAndFifosAreRefusedAtOnce) {
  TempDir dir;
  fs::create_symlink("/dev/zero", dir.file("zero.glb"));
  std::string msg = expectError(dir.file("zero.glb"), gi::ErrorKind::FileNotFound);
  EXPECT_TRUE(contains(msg, "not a regular file")) << msg;
  ASSERT_EQ(::mkfifo(dir.file("fifo.gltf").c_str(), 0600), 0);
  msg = expectError(dir.file("fifo.gltf"), gi::ErrorKind::FileNotFound);
  EXPECT_TRUE(contains(msg, "not a regular file")) << msg;
}
