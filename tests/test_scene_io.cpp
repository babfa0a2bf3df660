// Scene loading: OBJ/PLY models, the built-in scene, JSON scene files and their errors.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include "gi/errors.h"
#include "gi/input_file.h"
#include "gi/scene_io.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace {

// A fresh folder per test for files written on the fly.
class TempDir : public gi::test::TempDir {
 public:
  TempDir() : gi::test::TempDir("test_scene_io") {}
};

// Runs `load` and checks that it throws gi::Error of `kind` whose message names `file` (and
// contains `fragment`, when given).
void expectError(const std::function<void()>& load, gi::ErrorKind kind, const std::string& file,
                 const std::string& fragment = "") {
  try {
    load();
    ADD_FAILURE() << "expected " << gi::errorKindName(kind) << " for " << file;
  } catch (const gi::Error& e) {
    EXPECT_EQ(e.kind(), kind) << "got " << gi::errorKindName(e.kind()) << ": " << e.what();
    EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
    if (!fragment.empty()) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  }
}

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
bool finite(const glm::mat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

// Geometry is usable: finite, unit normals, one area per triangle, indices in range.
void expectSaneScene(const gi::Scene& s) {
  ASSERT_FALSE(s.materials.empty());
  for (const gi::Mesh& m : s.meshes) {
    EXPECT_EQ(m.triangleAreas.size(), m.triangleCount()) << m.name;
    EXPECT_LT(m.material, s.materials.size()) << m.name;
    for (const gi::Vertex& v : m.vertices) {
      ASSERT_TRUE(finite(v.position)) << m.name;
      ASSERT_NEAR(glm::length(v.normal), 1.0f, 1e-3f) << m.name;
    }
    for (uint32_t i : m.indices) ASSERT_LT(i, m.vertices.size()) << m.name;
    for (float a : m.triangleAreas) ASSERT_TRUE(std::isfinite(a) && a > 0.0f) << m.name;
  }
  for (const gi::Node& n : s.nodes) EXPECT_TRUE(finite(n.world)) << n.name;
  ASSERT_GE(s.activeCameraNode, 0);
  EXPECT_GE(s.nodes[s.activeCameraNode].camera, 0);
  EXPECT_FALSE(s.lights.empty());
}

const char* kTriangleObj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

// Triangles a fan triangulation makes of the OBJ's faces, counted from the text.
size_t objTriangles(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  size_t triangles = 0;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string kw, corner;
    if (!(words >> kw) || kw != "f") continue;
    size_t corners = 0;
    while (words >> corner) ++corners;
    triangles += corners - 2;
  }
  return triangles;
}

size_t plyHeaderFaces(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line) && line.rfind("end_header", 0) != 0) {
    std::istringstream words(line);
    std::string a, b;
    size_t n = 0;
    if (words >> a >> b >> n && a == "element" && b == "face") return n;
  }
  return 0;
}

// ---------------------------------------------------------------------------------------------
// OBJ / PLY

TEST(SceneIo, CornellBoxObj) {
  const std::string path = gi::test::modelAsset("cornell_box/cornell_box.obj");
  gi::Scene s = gi::loadScene(path);
  expectSaneScene(s);
  const size_t expected = objTriangles(path);
  EXPECT_EQ(expected, 36u);  // 18 quads (SOURCE.txt); the front wall's face is commented out
  EXPECT_EQ(s.triangleCount(), expected);
  bool emissive = false;
  for (const gi::Mesh& m : s.meshes) {
    const gi::Material& mat = s.materials[m.material];
    EXPECT_EQ(m.name, mat.name);  // one mesh per material group
    if (mat.name == "light") {
      EXPECT_FLOAT_EQ(mat.emission.x, 20.0f);
      EXPECT_EQ(m.triangleCount(), 2u);
      emissive = true;
    } else {
      EXPECT_EQ(mat.emission, glm::vec3(0.0f)) << mat.name;
    }
    if (mat.name == "red") {
      EXPECT_EQ(glm::vec3(mat.baseColor), glm::vec3(1, 0, 0));
    }
  }
  EXPECT_TRUE(emissive);
  // Flat faces: the floor's normals point up (its winding faces into the box).
  for (const gi::Mesh& m : s.meshes) {
    if (m.name != "green") continue;
    for (const gi::Vertex& v : m.vertices) EXPECT_NEAR(v.normal.x, 1.0f, 1e-4f);
  }
}

TEST(SceneIo, BunnyPly) {
  const std::string path = gi::test::modelAsset("stanford_bunny/bun_zipper.ply");
  gi::Scene s = gi::loadScene(path);
  expectSaneScene(s);
  EXPECT_EQ(plyHeaderFaces(path), 69451u);
  EXPECT_EQ(s.triangleCount(), plyHeaderFaces(path));
  ASSERT_EQ(s.meshes.size(), 1u);
  EXPECT_LE(s.meshes[0].vertices.size(), 35947u);  // unreferenced vertices are removed
  EXPECT_GT(s.meshes[0].vertices.size(), 34000u);
  EXPECT_EQ(s.lights[0].type, gi::LightType::Directional);  // the default sun
}

TEST(SceneIo, ObjPolygonsGroupsAndRelativeIndices) {
  TempDir dir;
  dir.write("m.mtl",
            "newmtl a\nKd 0.5 0.25 1\nNs 98\n"
            "newmtl glow\nKe 1 2 3\n"
            "newmtl lamp_light\nKa 4 4 4\n"
            "newmtl ambient\nKa 4 4 4\n");
  const std::string obj = dir.write("m.obj",
                                    "mtllib m.mtl\n"
                                    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 1.5 0\n"
                                    "vn 0 0 1\nvt 0 0\nvt 1 1\n"
                                    "usemtl a\nf 1/1/1 2/2/1 3//1 5 4\n"  // pentagon: 3 triangles
                                    "usemtl glow\nf -5 -4 -3\n"           // relative indices
                                    "usemtl lamp_light\nf 1 2 3\n"
                                    "usemtl ambient\nf 1 2 3\n"
                                    "usemtl a\r\nf 1 3 4\n");  // back to a, CRLF line end
  gi::Scene s = gi::loadMeshFile(obj);
  EXPECT_EQ(s.triangleCount(), 7u);
  ASSERT_EQ(s.meshes.size(), 4u);
  for (const gi::Mesh& m : s.meshes) {
    const gi::Material& mat = s.materials[m.material];
    if (mat.name == "a") {
      EXPECT_EQ(m.triangleCount(), 4u);
      EXPECT_FLOAT_EQ(mat.baseColor.y, 0.25f);
      EXPECT_NEAR(mat.roughness, 0.1414f, 1e-3f);
      EXPECT_FLOAT_EQ(m.vertices[0].uv.y, 1.0f);  // flipped: OBJ's v points up
    }
    if (mat.name == "glow") {
      EXPECT_EQ(mat.emission, glm::vec3(1, 2, 3));
    } else if (mat.name == "lamp_light") {
      EXPECT_EQ(mat.emission, glm::vec3(4));  // Ka of a light
    } else if (mat.name == "ambient") {
      EXPECT_EQ(mat.emission, glm::vec3(0));  // Ka is only ambient
    }
  }
  expectSaneScene(s);
}

TEST(SceneIo, ObjSmoothingGroupsShareVertices) {
  TempDir dir;
  // Two triangles folded along the shared edge 2-3.
  const std::string geometry = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
  gi::Scene flat = gi::loadMeshFile(dir.write("flat.obj", geometry + "f 1 2 3\nf 1 4 2\n"));
  gi::Scene smooth =
      gi::loadMeshFile(dir.write("smooth.obj", geometry + "s 1\nf 1 2 3\nf 1 4 2\n"));
  EXPECT_EQ(flat.meshes[0].vertices.size(), 6u);    // each face its own corners
  EXPECT_EQ(smooth.meshes[0].vertices.size(), 4u);  // shared, normals averaged
  for (const gi::Vertex& v : flat.meshes[0].vertices)
    EXPECT_NEAR(std::abs(v.normal.y) + std::abs(v.normal.z), 1.0f, 1e-5f);  // a face normal
}

TEST(SceneIo, ObjErrors) {
  TempDir dir;
  using K = gi::ErrorKind;
  const std::string v3 = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  std::string p = dir.path("missing.obj");
  expectError([&] { gi::loadMeshFile(p); }, K::FileNotFound, p);
  p = dir.write("empty.obj", "");
  expectError([&] { gi::loadScene(p); }, K::EmptyFile, p);
  p = dir.write("blank.obj", "  \n\n");
  expectError([&] { gi::loadScene(p); }, K::EmptyFile, p);
  p = dir.write("badnum.obj", "v 0 0 x\n");
  expectError([&] { gi::loadScene(p); }, K::Parse, p, "line 1");
  p = dir.write("short.obj", v3 + "f 1 2\n");
  expectError([&] { gi::loadScene(p); }, K::Parse, p, "line 4");
  p = dir.write("range.obj", v3 + "f 1 2 4\n");
  expectError([&] { gi::loadScene(p); }, K::IndexOutOfRange, p, "line 4");
  p = dir.write("zero.obj", v3 + "f 0 1 2\n");
  expectError([&] { gi::loadScene(p); }, K::IndexOutOfRange, p);
  p = dir.write("negative.obj", v3 + "f -1 -2 -4\n");
  expectError([&] { gi::loadScene(p); }, K::IndexOutOfRange, p);
  p = dir.write("normal.obj", v3 + "f 1//1 2//1 3//1\n");
  expectError([&] { gi::loadScene(p); }, K::IndexOutOfRange, p, "normal");
  p = dir.write("nofaces.obj", v3 + "# just points\n");
  expectError([&] { gi::loadScene(p); }, K::InvalidData, p);
  p = dir.write("nan.obj", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  expectError([&] { gi::loadScene(p); }, K::NonFinite, p);
  p = dir.write("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");  // collinear only
  expectError([&] { gi::loadScene(p); }, K::InvalidData, p);
}

TEST(SceneIo, ObjNaNTrianglesDroppedWithWarning) {
  TempDir dir;
  const std::string p = dir.write(
      "m.obj", "mtllib nowhere.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv inf 0 0\nf 1 2 3\nf 1 2 4\n");
  gi::Scene s = gi::loadMeshFile(p);
  EXPECT_EQ(s.triangleCount(), 1u);
  std::string all;
  for (const std::string& w : s.warnings) all += w + "\n";
  EXPECT_NE(all.find("NaN/Inf"), std::string::npos) << all;
  EXPECT_NE(all.find("nowhere.mtl"), std::string::npos) << all;
  expectSaneScene(s);
}

TEST(SceneIo, ObjNormalWarningsOnlyForInvalidNormals) {
  TempDir dir;
  // Absent normals are computed silently; a NaN normal is repaired with a warning.
  gi::Scene quiet = gi::loadMeshFile(dir.write("a.obj", kTriangleObj));
  EXPECT_TRUE(quiet.warnings.empty());
  gi::Scene loud = gi::loadMeshFile(
      dir.write("b.obj", std::string(kTriangleObj) + "vn nan 0 0\nvn 0 0 1\nf 1//1 2//2 3//2\n"));
  ASSERT_EQ(loud.warnings.size(), 1u);
  EXPECT_NE(loud.warnings[0].find("1 invalid"), std::string::npos) << loud.warnings[0];
  expectSaneScene(loud);
}

std::string plyHeader(int vertices, int faces) {
  return "ply\nformat ascii 1.0\ncomment test\nelement vertex " + std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
         std::to_string(faces) + "\nproperty list uchar int vertex_indices\nend_header\n";
}

TEST(SceneIo, PlyAsciiAndBinary) {
  TempDir dir;
  // A quad (fan-triangulated) and a triangle with a repeated corner (dropped as degenerate).
  gi::Scene s = gi::loadMeshFile(
      dir.write("a.ply", plyHeader(4, 2) + "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n3 0 1 1\n"));
  EXPECT_EQ(s.triangleCount(), 2u);
  expectSaneScene(s);

  std::string bin =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  const float xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  bin.append(reinterpret_cast<const char*>(xyz), sizeof(xyz));
  const unsigned char n = 3;
  const int32_t idx[3] = {0, 1, 2};
  bin.append(reinterpret_cast<const char*>(&n), 1);
  bin.append(reinterpret_cast<const char*>(idx), sizeof(idx));
  gi::Scene b = gi::loadMeshFile(dir.write("b.ply", bin));
  EXPECT_EQ(b.triangleCount(), 1u);
  EXPECT_NEAR(b.meshes[0].triangleAreas[0], 0.5f, 1e-6f);
}

TEST(SceneIo, PlyErrors) {
  TempDir dir;
  using K = gi::ErrorKind;
  std::string p = dir.write("empty.ply", "");
  expectError([&] { gi::loadScene(p); }, K::EmptyFile, p);
  // OpenMesh alone never returns on a header cut short; we must.
  p = dir.write("cut.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nprop");
  expectError([&] { gi::loadScene(p); }, K::Parse, p);
  p = dir.write("notply.ply", "hello\n");
  expectError([&] { gi::loadScene(p); }, K::Parse, p);
  p = dir.write("range.ply", plyHeader(3, 1) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
  expectError([&] { gi::loadScene(p); }, K::IndexOutOfRange, p, "7");
  p = dir.write("truncated.ply", plyHeader(3, 2) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  expectError([&] { gi::loadScene(p); }, K::Parse, p);
  p = dir.write("huge.ply", plyHeader(1000000000, 1) + "0 0 0\n");
  expectError([&] { gi::loadScene(p); }, K::Parse, p);
  p = dir.write("points.ply", plyHeader(3, 0) + "0 0 0\n1 0 0\n0 1 0\n");
  expectError([&] { gi::loadScene(p); }, K::InvalidData, p);
}

// ---------------------------------------------------------------------------------------------
// Built-in scene and defaults

TEST(SceneIo, DefaultScene) {
  gi::Scene s = gi::loadScene("default");
  EXPECT_EQ(s.sourcePath, "default");
  expectSaneScene(s);
  ASSERT_EQ(s.cameras.size(), 1u);
  EXPECT_GE(s.lights.size(), 1u);
  EXPECT_EQ(s.environment.kind, gi::Environment::Kind::Sky);

  // Walls, floor and ceiling face into the room; every mesh's winding matches its normals.
  int emissiveQuads = 0;
  for (const gi::Node& n : s.nodes) {
    for (int mi : n.meshes) {
      const gi::Mesh& m = s.meshes[mi];
      for (size_t t = 0; t < m.triangleCount(); ++t) {
        const gi::Vertex& a = m.vertices[m.indices[3 * t]];
        glm::vec3 geo = glm::cross(m.vertices[m.indices[3 * t + 1]].position - a.position,
                                   m.vertices[m.indices[3 * t + 2]].position - a.position);
        ASSERT_GT(glm::dot(geo, a.normal), 0.0f) << m.name << " triangle " << t;
      }
      if (n.name.find("wall") != std::string::npos || n.name == "floor" || n.name == "ceiling") {
        glm::vec3 p = glm::vec3(n.world * glm::vec4(m.vertices[0].position, 1.0f));
        glm::vec3 normal = glm::mat3(n.world) * m.vertices[0].normal;
        EXPECT_GT(glm::dot(normal, -p), 0.0f) << n.name;  // towards the room's centre
      }
      const gi::Material& mat = s.materials[m.material];
      if (mat.emission.x > 0.0f) {
        ++emissiveQuads;
        EXPECT_EQ(m.triangleCount(), 2u);
        glm::vec3 down = glm::mat3(n.world) * m.vertices[0].normal;
        EXPECT_LT(down.y, -0.99f);  // shines down from the ceiling
      }
    }
  }
  EXPECT_EQ(emissiveQuads, 1);
  EXPECT_GT(s.triangleCount(), 32u * 16u);  // the sphere alone has ~2 * 32 * 15

  // The camera stands in front of the open side and sees the room's centre ahead.
  gi::CameraView view = gi::activeCamera(s, 16.0f / 9.0f);
  EXPECT_GT(view.position.z, 1.0f);
  glm::vec3 centreInView = glm::vec3(view.view * glm::vec4(0, 0, 0, 1));
  EXPECT_LT(centreInView.z, 0.0f);
  EXPECT_NEAR(centreInView.x, 0.0f, 1e-4f);
}

TEST(SceneIo, DefaultCameraAndLightFrameTheModel) {
  TempDir dir;
  gi::Scene s = gi::loadMeshFile(dir.write("t.obj", "v 10 0 0\nv 12 0 0\nv 10 2 0\nf 1 2 3\n"));
  ASSERT_EQ(s.cameras.size(), 1u);
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_TRUE(s.lights[0].castsShadows);
  gi::CameraView view = gi::activeCamera(s, 1.0f);
  glm::vec3 c = glm::vec3(view.view * glm::vec4(11, 1, 0, 1));  // bounds centre
  EXPECT_NEAR(c.x, 0.0f, 1e-3f);
  EXPECT_NEAR(c.y, 0.0f, 1e-3f);
  EXPECT_LT(c.z, 0.0f);
  EXPECT_GT(-c.z, view.znear);
  EXPECT_LT(-c.z, view.zfar);
  // The sun shines downwards (along its node's -z).
  for (const gi::Node& n : s.nodes) {
    if (n.light >= 0) {
      EXPECT_LT((n.world * glm::vec4(0, 0, -1, 0)).y, -0.5f);
    }
  }

  // Scenes that have both keep them.
  size_t nodes = s.nodes.size();
  gi::addDefaultCameraAndLight(s);
  EXPECT_EQ(s.nodes.size(), nodes);
}

TEST(SceneIo, UnsupportedAndMissing) {
  TempDir dir;
  std::string p = dir.write("x.fbx", "data");
  expectError([&] { gi::loadScene(p); }, gi::ErrorKind::Unsupported, p);
  p = dir.path("nothing.gltf");
  expectError([&] { gi::loadScene(p); }, gi::ErrorKind::FileNotFound, p);
  p = dir.path("nothing.stl");
  expectError([&] { gi::loadScene(p); }, gi::ErrorKind::FileNotFound, p);
}

// ---------------------------------------------------------------------------------------------
// JSON scenes

// World position of the model's first vertex (the node holding mesh `mesh`).
glm::vec3 worldOfFirstVertex(const gi::Scene& s, int mesh) {
  for (const gi::Node& n : s.nodes)
    for (int m : n.meshes)
      if (m == mesh) return glm::vec3(n.world * glm::vec4(s.meshes[m].vertices[0].position, 1));
  ADD_FAILURE() << "no node holds mesh " << mesh;
  return glm::vec3(NAN);
}

void expectVec(const glm::vec3& a, const glm::vec3& b, float eps = 1e-4f) {
  EXPECT_NEAR(a.x, b.x, eps);
  EXPECT_NEAR(a.y, b.y, eps);
  EXPECT_NEAR(a.z, b.z, eps);
}

TEST(SceneIo, JsonSceneWithModelAndOverrides) {
  TempDir dir;
  dir.write("models/tri.obj", kTriangleObj);
  const std::string path = dir.write("scene.json", R"({
    // comments are allowed
    "description": "test",
    "models": [
      { "file": "models/tri.obj", "name": "moved", "translation": [1, 2, 3], "scale": 2 },
      { "file": "models/tri.obj", "rotation": [0, 90, 0] },
      { "file": "models/tri.obj", "rotation": [0, 0, 0.7071068, 0.7071068], "scale": [1, 3, 1] },
      { "primitive": "sphere", "radius": 0.5, "segments": 8, "rings": 4,
        "material": { "name": "glow", "base_color": [1, 0, 0], "emission": [2, 2, 2] } },
      { "primitive": "box", "size": [1, 2, 3], "translation": [0, -5, 0] },
      { "primitive": "plane", "size": [4, 2] }
    ],
    "camera": { "position": [0, 1, 5], "target": [0, 1, 0], "yfov_deg": 60, "near": 0.5, "far": 50 },
    "lights": [
      { "type": "point", "position": [0, 3, 0], "color": [1, 0.5, 0.25], "intensity": 7, "range": 9 },
      { "type": "spot", "position": [1, 1, 1], "direction": [0, 0, -1], "inner_cone_deg": 10,
        "outer_cone_deg": 20, "casts_shadows": false },
      { "type": "directional", "direction": [0, -1, 0] }
    ],
    "environment": { "type": "constant", "color": [0.1, 0.2, 0.3], "intensity": 2 },
    "effects": [ "ssao", { "name": "ssdo", "settings": { "radius": 0.5, "bounce": true } } ]
  })");
  gi::Scene s = gi::loadScene(path);
  expectSaneScene(s);
  ASSERT_EQ(s.meshes.size(), 6u);
  EXPECT_EQ(s.sourcePath, path);

  // Vertex (0,0,0) scaled by 2 then moved; (0,0,0) of the rotated ones stays; check a corner.
  expectVec(worldOfFirstVertex(s, 0), {1, 2, 3});
  EXPECT_EQ(s.nodes[s.roots[0]].name, "moved");
  EXPECT_EQ(s.nodes[s.roots[1]].name, "tri");  // defaults to the file's stem
  // Second vertex (1,0,0): Euler 90 deg about y -> (0,0,-1); quaternion 90 deg about z after
  // scaling y by 3 -> (0,1,0).
  auto worldOf = [&](int mesh, int vertex) {
    for (const gi::Node& n : s.nodes)
      for (int m : n.meshes)
        if (m == mesh)
          return glm::vec3(n.world * glm::vec4(s.meshes[m].vertices[vertex].position, 1));
    return glm::vec3(NAN);
  };
  expectVec(worldOf(1, 1), {0, 0, -1});
  expectVec(worldOf(2, 1), {0, 1, 0});
  // Primitives: a sphere with its material, a box of the given size, a plane.
  const gi::Material& glow = s.materials[s.meshes[3].material];
  EXPECT_EQ(glow.name, "glow");
  EXPECT_EQ(glow.emission, glm::vec3(2));
  expectVec(s.meshes[3].boundsMax, {0.5f, 0.5f, 0.5f});
  expectVec(s.meshes[4].boundsMax, {0.5f, 1.0f, 1.5f});
  expectVec(s.meshes[5].boundsMax, {2.0f, 0.0f, 1.0f});
  EXPECT_EQ(s.meshes[4].triangleCount(), 12u);

  // The JSON camera is the active one.
  gi::CameraView view = gi::activeCamera(s, 1.0f);
  expectVec(view.position, {0, 1, 5});
  expectVec(glm::vec3(view.view * glm::vec4(0, 1, 0, 1)), {0, 0, -5});
  EXPECT_NEAR(view.yfov, glm::radians(60.0f), 1e-5f);
  EXPECT_FLOAT_EQ(view.znear, 0.5f);

  ASSERT_EQ(s.lights.size(), 3u);  // no default sun added
  EXPECT_EQ(s.lights[0].type, gi::LightType::Point);
  EXPECT_FLOAT_EQ(s.lights[0].intensity, 7.0f);
  EXPECT_FLOAT_EQ(s.lights[0].range, 9.0f);
  EXPECT_EQ(s.lights[1].type, gi::LightType::Spot);
  EXPECT_NEAR(s.lights[1].outerConeAngle, glm::radians(20.0f), 1e-6f);
  EXPECT_FALSE(s.lights[1].castsShadows);
  EXPECT_TRUE(s.lights[2].castsShadows);
  for (const gi::Node& n : s.nodes) {
    if (n.light == 1) {  // a spot pointing along -z from (1, 1, 1)
      expectVec(glm::vec3(n.world[3]), {1, 1, 1});
      expectVec(glm::vec3(n.world * glm::vec4(0, 0, -1, 0)), {0, 0, -1});
    }
    if (n.light == 2) expectVec(glm::vec3(n.world * glm::vec4(0, 0, -1, 0)), {0, -1, 0});
  }
  EXPECT_EQ(s.environment.kind, gi::Environment::Kind::Constant);
  expectVec(s.environment.constantColor, {0.1f, 0.2f, 0.3f});
  EXPECT_FLOAT_EQ(s.environment.intensity, 2.0f);
  ASSERT_EQ(s.effects.size(), 2u);
  EXPECT_EQ(s.effects[0].name, "ssao");
  EXPECT_TRUE(s.effects[0].settings.empty());
  EXPECT_EQ(s.effects[1].name, "ssdo");
  EXPECT_EQ(s.effects[1].settings["radius"], 0.5);
  EXPECT_EQ(s.effects[1].settings["bounce"], true);
}

TEST(SceneIo, JsonDefaultSceneAndDefaults) {
  TempDir dir;
  gi::Scene base = gi::makeDefaultScene();
  gi::Scene s = gi::loadScene(
      dir.write("s.json", R"({"include_default_scene": true, "models": [{"primitive": "box"}]})"));
  EXPECT_EQ(s.meshes.size(), base.meshes.size() + 1);
  EXPECT_EQ(s.lights.size(), base.lights.size());
  EXPECT_EQ(s.nodes[s.activeCameraNode].name, "camera");  // the default scene's camera

  // A bare model: framed camera and a sun are added.
  dir.write("t.obj", kTriangleObj);
  gi::Scene bare = gi::loadScene(dir.write("b.json", R"({"models": [{"file": "t.obj"}]})"));
  EXPECT_EQ(bare.cameras.size(), 1u);
  ASSERT_EQ(bare.lights.size(), 1u);
  EXPECT_EQ(bare.lights[0].type, gi::LightType::Directional);
  expectSaneScene(bare);
}

TEST(SceneIo, JsonPathVariables) {
  TempDir dir;
  const std::string engine =
      gi::test::assimpModel("glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb");
  if (fs::exists(engine)) {
    gi::Scene s = gi::loadScene(dir.write(
        "a.json",
        R"({"models": [{"file": "${ASSIMP_MODELS}/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb"}]})"));
    EXPECT_GT(s.triangleCount(), 1000u);
  }
  // ${ASSIMP_MODELS} from the environment variable.
  dir.write("assets/t.obj", kTriangleObj);
  ::setenv("ASSIMP_MODELS", dir.path("assets").c_str(), 1);
  gi::Scene s =
      gi::loadScene(dir.write("s.json", R"({"models": [{"file": "${ASSIMP_MODELS}/t.obj"}]})"));
  ::unsetenv("ASSIMP_MODELS");
  EXPECT_EQ(s.triangleCount(), 1u);
  // Nothing is searched for above the scene file: a variable for a folder there is unknown.
  dir.write("shared/assets/u.obj", kTriangleObj);
  const std::string above =
      dir.write("deep/er/s.json", R"({"models": [{"file": "${SHARED}/u.obj"}]})");
  expectError([&] { gi::loadScene(above); }, gi::ErrorKind::Schema, above,
              "unknown variable '${SHARED}' (known: ${ASSIMP_MODELS}");
  const std::string bad = dir.write("v.json", R"({"models": [{"file": "${NOPE}/u.obj"}]})");
  expectError([&] { gi::loadScene(bad); }, gi::ErrorKind::Schema, bad, "NOPE");
}

// "grid": copies of a model sharing its meshes, offset per cell; and the box's "segments".
TEST(SceneIo, JsonGridRepeatsAModelSharingItsMeshes) {
  TempDir dir;
  const gi::Scene s = gi::loadScene(dir.write("grid.json", R"({"models": [
      {"primitive": "box", "size": 0.5, "segments": 2, "translation": [1, 2, 3],
       "grid": {"counts": [3, 2, 4], "spacing": [2, 1, 0.5]}}]})"));
  ASSERT_EQ(s.meshes.size(), 1u) << "the copies share the mesh";
  EXPECT_EQ(s.meshes[0].indices.size(), 48u * 3u) << "2 x 2 quads on each of six faces";
  std::vector<glm::vec3> origins;
  for (const gi::Node& n : s.nodes)
    if (!n.meshes.empty()) origins.push_back(glm::vec3(n.world[3]));
  ASSERT_EQ(origins.size(), 24u);
  glm::vec3 lo(1e9f), hi(-1e9f);
  for (const glm::vec3& o : origins) {
    lo = glm::min(lo, o);
    hi = glm::max(hi, o);
  }
  EXPECT_EQ(lo, glm::vec3(1, 2, 3));
  EXPECT_EQ(hi, glm::vec3(1 + 2 * 2, 2 + 1 * 1, 3 + 3 * 0.5f));
  const std::string anim = dir.write("anim.json", R"({"models": [{"primitive": "box",
      "grid": {"counts": [2, 1, 1]}, "animation": {"orbit": {"center": [0, 0, 0], "period": 2}}}]})");
  expectError([&] { gi::loadScene(anim); }, gi::ErrorKind::InvalidData, anim,
              "models[0].grid: a model with animation");
  for (const char* bad : {"[0, 1, 1]", "[1.5, 1, 1]", "[1001, 1000, 1000]", "[1, 1]"}) {
    const std::string f = dir.write("bad.json", std::string(R"({"models": [{"primitive": "box",
        "grid": {"counts": )") + bad + "}}]}");
    EXPECT_THROW(gi::loadScene(f), gi::Error) << bad;
  }
  const std::string seg =
      dir.write("seg.json", R"({"models": [{"primitive": "box", "segments": 0}]})");
  expectError([&] { gi::loadScene(seg); }, gi::ErrorKind::InvalidData, seg, "segments");
}

// Regions: named world boxes for per-region scores; the shipped benchmark scenes define theirs.
TEST(SceneIo, RegionsAreNamedBoxes) {
  TempDir dir;
  const gi::Scene s = gi::loadScene(dir.write("r.json", R"({
      "models": [ { "primitive": "plane", "size": 2 } ],
      "regions": [ { "name": "floor", "min": [-1, -0.01, -1], "max": [1, 0.01, 1] },
                   { "name": "above", "min": [-1, 0.5, -1], "max": [1, 1, 1] } ] })"));
  ASSERT_EQ(s.regions.size(), 2u);
  EXPECT_EQ(s.regions[0].name, "floor");
  EXPECT_TRUE(s.regions[0].contains({0.5f, 0.0f, -0.5f}));
  EXPECT_FALSE(s.regions[0].contains({0.5f, 0.2f, -0.5f}));
  EXPECT_TRUE(s.regions[1].contains({0.0f, 1.0f, 0.0f}));  // bounds included
  EXPECT_EQ(gi::loadScene("default").regions.size(), 7u);
  for (const char* scene : {"cornell_box.json", "bunny_on_plane.json"})
    EXPECT_GE(gi::loadScene(std::string(GI_SOURCE_DIR) + "/assets/scenes/" + scene).regions.size(),
              3u)
        << scene;
}

TEST(SceneIo, JsonErrors) {
  TempDir dir;
  using K = gi::ErrorKind;
  dir.write("t.obj", kTriangleObj);
  dir.write("broken.obj", "v 0 0 0\nf 1 2 3\n");
  struct Case {
    const char* name;
    const char* json;
    K kind;
    const char* fragment;
  };
  const Case cases[] = {
      {"unknown_top", R"({"model": []})", K::Schema, "model: unknown key"},
      {"unknown_light",
       R"({"lights": [{"type": "point", "position": [0, 0, 0], "colour": [1, 1, 1]}]})", K::Schema,
       "lights[0].colour: unknown key"},
      {"unknown_model_key", R"({"models": [{"file": "t.obj", "scal": 2}]})", K::Schema,
       "models[0].scal: unknown key"},
      {"unknown_effect_key", R"({"effects": [{"name": "ssao", "setting": {}}]})", K::Schema,
       "effects[0].setting"},
      {"wrong_type_intensity",
       R"({"lights": [{"type": "point", "position": [0, 0, 0], "intensity": "bright"}]})",
       K::Schema, "lights[0].intensity: expected a number"},
      {"wrong_type_models", R"({"models": {"file": "t.obj"}})", K::Schema, "models"},
      {"wrong_type_top", R"([1, 2])", K::Schema, "expected an object"},
      {"wrong_length", R"({"camera": {"position": [0, 0], "target": [0, 0, 1]}})", K::Schema,
       "camera.position"},
      {"wrong_elem", R"({"camera": {"position": [0, "a", 0], "target": [0, 0, 1]}})", K::Schema,
       "camera.position[1]"},
      {"wrong_bool", R"({"include_default_scene": 1})", K::Schema, "include_default_scene"},
      {"region_without_max", R"({"regions": [{"name": "floor", "min": [0, 0, 0]}]})", K::Schema,
       "regions[0].max"},
      {"region_inverted", R"({"regions": [{"name": "floor", "min": [0, 1, 0], "max": [1, 0, 1]}]})",
       K::InvalidData, "regions[0].max: must be at least min"},
      {"region_twice",
       R"({"regions": [{"name": "a", "min": [0, 0, 0], "max": [1, 1, 1]},
                       {"name": "a", "min": [0, 0, 0], "max": [1, 1, 1]}]})",
       K::InvalidData, "regions[1].name: 'a' is used twice"},
      {"missing_key", R"({"camera": {"target": [0, 0, 1]}})", K::Schema,
       "camera.position: missing required key"},
      {"light_type", R"({"lights": [{"type": "area", "position": [0, 0, 0]}]})", K::Schema,
       "lights[0].type"},
      {"point_direction",
       R"({"lights": [{"type": "point", "position": [0, 0, 0], "direction": [0, -1, 0]}]})",
       K::Schema, "lights[0].direction"},
      {"file_and_primitive", R"({"models": [{"file": "t.obj", "primitive": "box"}]})", K::Schema,
       "models[0]"},
      {"primitive_kind", R"({"models": [{"primitive": "torus"}]})", K::Schema, "torus"},
      {"primitive_key", R"({"models": [{"primitive": "box", "radius": 1}]})", K::Schema,
       "models[0].radius"},
      {"env_key", R"({"environment": {"type": "sky", "color": [1, 1, 1]}})", K::Schema,
       "environment.color"},
      {"effect_type", R"({"effects": [3]})", K::Schema, "effects[0]"},
      {"yfov", R"({"camera": {"position": [0, 0, 0], "target": [0, 0, 1], "yfov_deg": 0}})",
       K::InvalidData, "camera.yfov_deg"},
      {"same_target", R"({"camera": {"position": [0, 0, 0], "target": [0, 0, 0]}})", K::InvalidData,
       "camera.target"},
      {"negative_intensity",
       R"({"lights": [{"type": "point", "position": [0, 0, 0], "intensity": -1}]})", K::InvalidData,
       "lights[0].intensity"},
      {"zero_scale", R"({"models": [{"file": "t.obj", "scale": [1, 0, 1]}]})", K::InvalidData,
       "models[0].scale"},
      {"nested_scene", R"({"models": [{"file": "other.json"}]})", K::MissingResource, "other.json"},
      {"fbx", R"({"models": [{"file": "t.fbx"}]})", K::MissingResource, "t.fbx"},
      {"invalid_json", "{\"models\": [\n  {\"file\": }\n]}", K::Parse, "line 2"},
      {"trailing_comma", R"({"models": [],})", K::Parse, "line 1"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = dir.write(std::string(c.name) + ".json", c.json);
    expectError([&] { gi::loadScene(path); }, c.kind, path, c.fragment);
  }

  // A model file that is missing: named along with the scene file.
  std::string p = dir.write("missing_model.json", R"({"models": [{"file": "gone/none.obj"}]})");
  expectError([&] { gi::loadScene(p); }, K::MissingResource, p, "none.obj");
  // A model that exists but is not a model format.
  dir.write("x.fbx", "data");
  p = dir.write("fbx2.json", R"({"models": [{"file": "x.fbx"}]})");
  expectError([&] { gi::loadScene(p); }, K::Unsupported, p, "x.fbx");
  // A broken model keeps its own error kind and file, and names the scene too.
  p = dir.write("broken_model.json", R"({"models": [{"file": "broken.obj"}]})");
  expectError([&] { gi::loadScene(p); }, K::IndexOutOfRange, dir.path("broken.obj"),
              "broken_model.json");
  // Empty and missing scene files.
  p = dir.write("empty.json", "");
  expectError([&] { gi::loadScene(p); }, K::EmptyFile, p);
  p = dir.write("blank.json", " \n\t\n");
  expectError([&] { gi::loadScene(p); }, K::EmptyFile, p);
  p = dir.path("nowhere.json");
  expectError([&] { gi::loadScene(p); }, K::FileNotFound, p);
  expectError([&] { gi::loadSceneJson(p); }, K::FileNotFound, p);
}

// The example scenes shipped in assets/scenes load and contain what they promise.
TEST(SceneIo, ExampleScenes) {
  const fs::path scenes = fs::path(GI_SOURCE_DIR) / "assets" / "scenes";
  {
    const std::string obj = gi::test::modelAsset("cornell_box/cornell_box.obj");
    gi::Scene s = gi::loadScene((scenes / "cornell_box.json").string());
    expectSaneScene(s);
    EXPECT_EQ(s.triangleCount(), objTriangles(obj));
    bool emissive = false;
    for (const gi::Mesh& m : s.meshes) emissive |= s.materials[m.material].emission.x > 0.0f;
    EXPECT_TRUE(emissive);
    glm::vec3 bmin, bmax;
    s.worldBounds(bmin, bmax);
    EXPECT_NEAR(bmax.x, 5.56f, 1e-3f);  // scaled from millimetres
  }
  {
    const std::string ply = gi::test::modelAsset("stanford_bunny/bun_zipper.ply");
    gi::Scene s = gi::loadScene((scenes / "bunny_on_plane.json").string());
    expectSaneScene(s);
    EXPECT_EQ(s.triangleCount(), plyHeaderFaces(ply) + 2);  // + the ground plane
    glm::vec3 bmin, bmax;
    s.worldBounds(bmin, bmax);
    EXPECT_NEAR(bmin.y, 0.0f, 1e-2f);  // the bunny stands on the plane
  }
  {
    // The room with the bunny inside it: the room's bounds (so from the room's camera the same
    // pixels are geometry, docs/bench/ao/triangles), the bunny's triangles added.
    const std::string ply = gi::test::modelAsset("stanford_bunny/bun_zipper.ply");
    const gi::Scene room = gi::makeDefaultScene();
    gi::Scene s = gi::loadScene((scenes / "room_bunny.json").string());
    expectSaneScene(s);
    EXPECT_EQ(s.triangleCount(), room.triangleCount() + plyHeaderFaces(ply));
    glm::vec3 bmin, bmax, rmin, rmax;
    s.worldBounds(bmin, bmax);
    room.worldBounds(rmin, rmax);
    EXPECT_LT(glm::distance(bmin, rmin), 1e-3f);  // the bunny rests on the floor (y = -1)
    EXPECT_LT(glm::distance(bmax, rmax), 1e-3f);
  }
  const std::string glb =
      gi::test::assimpModel("glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb");
  if (!fs::exists(glb)) GTEST_SKIP() << "assimp test models absent: " << glb;
  gi::Scene s = gi::loadScene((scenes / "engine.json").string());
  expectSaneScene(s);
  EXPECT_GT(s.triangleCount(), 60000u);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// One standard for every input file (issue 15): only regular files are read, numbers are
// named when out of range, indices are reported as written.

TEST(SceneInputs, OnlyRegularFilesAreRead) {
  TempDir dir;
  fs::create_directories(dir.path("folder.json"));
  expectError([&] { gi::loadScene(dir.path("folder.json")); }, gi::ErrorKind::FileNotFound,
              "folder.json", "is a directory, not a file");
  // A FIFO would block until a writer comes; /dev/zero would be read until memory runs out.
  for (const char* name : {"fifo.json", "fifo.obj", "fifo.ply", "fifo.gltf"}) {
    ASSERT_EQ(::mkfifo(dir.path(name).c_str(), 0600), 0);
    expectError([&] { gi::loadScene(dir.path(name)); }, gi::ErrorKind::FileNotFound, name,
                "is not a regular file");
  }
  for (const char* name : {"zero.json", "zero.obj", "zero.ply", "zero.glb"}) {
    fs::create_symlink("/dev/zero", dir.path(name));
    expectError([&] { gi::loadScene(dir.path(name)); }, gi::ErrorKind::FileNotFound, name,
                "is not a regular file");
  }
  // A material library that is a FIFO: named, not waited on.
  ASSERT_EQ(::mkfifo(dir.path("lib.mtl").c_str(), 0600), 0);
  const std::string obj = dir.write("withlib.obj", std::string(kTriangleObj) + "mtllib lib.mtl\n");
  expectError([&] { gi::loadScene(obj); }, gi::ErrorKind::FileNotFound, "lib.mtl",
              "is not a regular file");
  // ... and so is the OBJ that names it, with its line (both files in the one message).
  expectError([&] { gi::loadScene(obj); }, gi::ErrorKind::FileNotFound,
              obj + ": line 5: mtllib lib.mtl: ", "lib.mtl: is not a regular file");
}

TEST(SceneInputs, SizeLimitAndReader) {
  TempDir dir;
  const std::string path = dir.write("ten.txt", "0123456789");
  EXPECT_EQ(gi::readInputFile(path), "0123456789");
  EXPECT_EQ(gi::checkInputFile(path), 10u);
  expectError([&] { gi::readInputFile(path, "file", 9); }, gi::ErrorKind::Unsupported, "ten.txt",
              "is 10 bytes; input files larger than 9 bytes are not read");
  std::vector<unsigned char> bytes;
  std::string problem;
  EXPECT_FALSE(gi::tryReadInputFile(dir.path("none"), bytes, problem));
  EXPECT_EQ(problem, "file does not exist");
}

TEST(SceneInputs, NumbersOutOfRangeAreNamed) {
  TempDir dir;
  const std::string json = dir.write("huge.json", R"({"camera": {"position": [0, 0, 1e400]}})");
  expectError([&] { gi::loadScene(json); }, gi::ErrorKind::InvalidData, "huge.json",
              "number '1e400' is out of range");
  const std::string obj = dir.write("huge.obj", "v 0 0 1e39\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  expectError([&] { gi::loadScene(obj); }, gi::ErrorKind::InvalidData, "huge.obj",
              "line 1: 1e39 is out of range for a float");
  // Below float range is zero, not an error; a word is still "not a number".
  const std::string tiny = dir.write("tiny.obj", "v 0 0 1e-60\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_EQ(gi::loadScene(tiny).triangleCount(), 1u);
  const std::string word = dir.write("word.obj", "v 0 0 x\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  expectError([&] { gi::loadScene(word); }, gi::ErrorKind::Parse, "word.obj",
              "line 1: x is not a number");
}

TEST(SceneInputs, PlyNegativeIndexIsReportedAsWritten) {
  TempDir dir;
  const std::string ply = dir.write("neg.ply",
                                    "ply\nformat ascii 1.0\nelement vertex 3\n"
                                    "property float x\nproperty float y\nproperty float z\n"
                                    "element face 1\nproperty list uchar int vertex_indices\n"
                                    "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n");
  expectError([&] { gi::loadScene(ply); }, gi::ErrorKind::IndexOutOfRange, "neg.ply",
              "face 0 uses vertex index -1 but there are only 3 vertices");
}

// Found by tools/fuzz: OpenMesh's header reader loops forever on a format line with extra
// words; every header line must now hold exactly its tokens.
TEST(SceneInputs, PlyHeaderLinesHoldExactlyTheirTokens) {
  TempDir dir;
  const std::string body =
      "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  EXPECT_EQ(gi::loadScene(dir.write("ok.ply", "ply\nformat ascii 1.0\n" + body)).triangleCount(),
            1u);
  expectError(
      [&] { gi::loadScene(dir.write("loop.ply", "ply\nformat ascii format ascii 1.0\n" + body)); },
      gi::ErrorKind::Parse, "loop.ply", "line 2: format version must be 1.0, got 'format'");
  expectError([&] { gi::loadScene(dir.write("extra.ply", "ply\nformat ascii 1.0 x\n" + body)); },
              gi::ErrorKind::Parse, "extra.ply", "line 2: format line: unexpected 'x'");
  expectError(
      [&] {
        gi::loadScene(dir.write("twice.ply", "ply\nformat ascii 1.0\nformat ascii 1.0\n" + body));
      },
      gi::ErrorKind::Parse, "twice.ply", "line 3: format line repeated");
  expectError(
      [&] {
        gi::loadScene(dir.write("prop.ply",
                                "ply\nformat ascii 1.0\nelement vertex 3\n"
                                "property float x junk\n" +
                                    body.substr(17)));
      },
      gi::ErrorKind::Parse, "prop.ply", "line 4: property line: unexpected 'junk'");
}

TEST(SceneInputs, ZeroSizeSceneIsAnErrorAndExtremeSizesWarn) {
  TempDir dir;
  // A hand-written glTF: one triangle under a node scaled by `s`.
  const std::string bin = std::string("\0\0\0\0\0\0\0\0\0\0\0\0", 12) +
                          std::string("\0\0\x80\x3f\0\0\0\0\0\0\0\0", 12) +
                          std::string("\0\0\0\0\0\0\x80\x3f\0\0\0\0", 12);
  dir.write("tri.bin", bin);
  auto gltf = [&](const std::string& name, const std::string& scale) {
    return dir.write(
        name, R"({"asset": {"version": "2.0"}, "buffers": [{"uri": "tri.bin", "byteLength": 36}],
          "bufferViews": [{"buffer": 0, "byteLength": 36}],
          "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}],
          "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
          "nodes": [{"mesh": 0, "scale": [)" +
                  scale + ", " + scale + ", " + scale + R"(]}], "scenes": [{"nodes": [0]}]})");
  };
  expectError([&] { gi::loadScene(gltf("zero.gltf", "0")); }, gi::ErrorKind::InvalidData,
              "zero.gltf", "the scene's geometry has zero size");
  expectError([&] { gi::loadScene(gltf("inf.gltf", "1e38")); }, gi::ErrorKind::NonFinite,
              "inf.gltf", "the scene's size is not finite");
  for (const char* scale : {"1e-6", "1e8"}) {
    const gi::Scene s = gi::loadScene(gltf("extreme.gltf", scale));
    std::string all;
    for (const std::string& w : s.warnings) all += w + "\n";
    EXPECT_NE(all.find("extreme.gltf: the scene is "), std::string::npos) << scale << ": " << all;
    EXPECT_NE(all.find(" units across"), std::string::npos) << all;
  }
  for (const std::string& w : gi::loadScene(gltf("unit.gltf", "1")).warnings)
    EXPECT_EQ(w.find("units across"), std::string::npos) << w;
}
