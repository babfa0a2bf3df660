// Wavefront OBJ + MTL reader.
//
// Parsed here rather than with OpenMesh's OBJ reader because that reader merges everything into
// one mesh and keeps materials only as face colours; we need one gi::Mesh per material
// (usemtl group) with its own gi::Material. Geometry still goes through processMesh (OpenMesh)
// afterwards.
//
// Supported: v, vt, vn, f (v, v/vt, v//vn, v/vt/vn, negative = relative indices, polygons are
// fan-triangulated), usemtl, mtllib, s (smoothing groups). o, g, l, p and other statements are
// ignored. Faces without normals are flat-shaded unless a smoothing group is active ("s 1"),
// as the OBJ format specifies; processMesh then computes the normals from the faces.
//
// Missing .mtl files, unknown material names and missing map_Kd images only produce warnings:
// the geometry is complete without them.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <limits>
#include <unordered_map>

#include <stb_image.h>

#include "gi/errors.h"
#include "gi/input_file.h"
#include "scene_io_util.h"

namespace gi::detail {
namespace {

namespace fs = std::filesystem;

// Splits a line into whitespace-separated tokens (views into the line).
std::vector<std::string_view> tokens(std::string_view line) {
  std::vector<std::string_view> out;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    size_t start = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

// Everything after the keyword, trimmed (names may contain spaces).
std::string restOfLine(std::string_view line, std::string_view keyword) {
  size_t at = line.find(keyword) + keyword.size();
  std::string_view rest = line.substr(at);
  while (!rest.empty() && std::isspace(static_cast<unsigned char>(rest.front())))
    rest.remove_prefix(1);
  while (!rest.empty() && std::isspace(static_cast<unsigned char>(rest.back())))
    rest.remove_suffix(1);
  return std::string(rest);
}

enum class FloatParse { Ok, NotANumber, OutOfRange };

FloatParse parseFloat(std::string_view s, float& out) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);  // from_chars rejects a '+'
  // Through double: a value beyond float range is named as such, one below it becomes 0.
  double d = 0.0;
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), d);
  if (end != s.data() + s.size() || (ec != std::errc() && ec != std::errc::result_out_of_range))
    return FloatParse::NotANumber;
  const bool tiny =
      s.find("e-") != std::string_view::npos || s.find("E-") != std::string_view::npos;
  if (ec == std::errc::result_out_of_range && !tiny) return FloatParse::OutOfRange;
  if (ec == std::errc::result_out_of_range) d = 0.0;
  if (std::isfinite(d) && std::abs(d) > double(std::numeric_limits<float>::max()))
    return FloatParse::OutOfRange;
  out = static_cast<float>(d);
  return FloatParse::Ok;
}

bool parseInt(std::string_view s, long& out) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && end == s.data() + s.size();
}

class LineError {
 public:
  LineError(const std::string& path, size_t line) : path_(path), line_(line) {}
  [[noreturn]] void fail(ErrorKind kind, const std::string& what) const {
    throw Error(kind, path_, "line " + std::to_string(line_) + ": " + what);
  }

 private:
  const std::string& path_;
  size_t line_;
};

// Reads `count` floats from tokens[1..]; extra tokens are allowed (e.g. vertex colours).
template <int N>
glm::vec<N, float> readVec(const std::vector<std::string_view>& tok, const LineError& err,
                           int required = N) {
  glm::vec<N, float> v(0.0f);
  // Messages are built with append: GCC 12 warns falsely (-Wrestrict) on "'" + string + ...
  if (static_cast<int>(tok.size()) - 1 < required)
    err.fail(
        ErrorKind::Parse,
        std::string(tok[0]).append(" needs ").append(std::to_string(required)).append(" numbers"));
  for (int i = 0; i < N && i + 1 < static_cast<int>(tok.size()); ++i)
    switch (parseFloat(tok[i + 1], v[i])) {
      case FloatParse::Ok:
        break;
      case FloatParse::OutOfRange:
        err.fail(ErrorKind::InvalidData,
                 std::string(tok[i + 1]).append(" is out of range for a float (beyond 3.4e38)"));
      case FloatParse::NotANumber:
        err.fail(ErrorKind::Parse, std::string(tok[i + 1]).append(" is not a number"));
    }
  return v;
}

bool nonZero(const glm::vec3& v) {
  return v.x > 0.0f || v.y > 0.0f || v.z > 0.0f;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// Calls fn(line, 1-based line number) for every line of `text` (without the '\n').
template <class Fn>
void forEachLine(const std::string& text, Fn&& fn) {
  size_t lineNo = 0, pos = 0;
  while (pos <= text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    fn(std::string_view(text.data() + pos, end - pos), ++lineNo);
    pos = end + 1;
  }
}

struct MtlEntry {
  Material material;
  glm::vec3 ka{0.0f};
  bool hasKe = false;
  bool hasNs = false;
  float ns = 0.0f;
  std::string mapKd;
};

// Parses an .mtl file into entries by name. Malformed numbers are errors (naming the .mtl).
std::unordered_map<std::string, MtlEntry> readMtl(const std::string& path) {
  std::unordered_map<std::string, MtlEntry> out;
  std::string text = readTextFile(path);
  MtlEntry* current = nullptr;
  forEachLine(text, [&](std::string_view line, size_t lineNo) {
    if (size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    auto tok = tokens(line);
    if (tok.empty()) return;
    LineError err(path, lineNo);
    if (tok[0] == "newmtl") {
      std::string name = restOfLine(line, "newmtl");
      current = &out[name];
      current->material.name = name;
      return;
    }
    if (!current) return;  // statements before the first newmtl have nothing to apply to
    if (tok[0] == "Kd") {
      glm::vec3 kd = readVec<3>(tok, err, 1);
      if (tok.size() == 2) kd = glm::vec3(kd.x);  // "Kd r" means grey
      current->material.baseColor = glm::vec4(kd, current->material.baseColor.a);
    } else if (tok[0] == "Ka") {
      current->ka = readVec<3>(tok, err, 1);
      if (tok.size() == 2) current->ka = glm::vec3(current->ka.x);
    } else if (tok[0] == "Ke") {
      glm::vec3 ke = readVec<3>(tok, err, 1);
      current->material.emission = tok.size() == 2 ? glm::vec3(ke.x) : ke;
      current->hasKe = true;
    } else if (tok[0] == "Ns") {
      current->ns = readVec<1>(tok, err).x;
      current->hasNs = true;
    } else if (tok[0] == "d") {
      current->material.baseColor.a = std::clamp(readVec<1>(tok, err).x, 0.0f, 1.0f);
    } else if (tok[0] == "map_Kd" && tok.size() >= 2) {
      current->mapKd = std::string(tok.back());  // options (-s, -o ...) come before the file
    }
  });
  return out;
}

// Turns an MTL entry into the material we render with.
Material toMaterial(const MtlEntry& e) {
  Material m = e.material;
  // Emission rule: Ke when present. Otherwise Ka counts as emission only for a material that is
  // clearly a light: non-zero Ka AND a name containing "light" or "emit" (the classic Cornell
  // box OBJ stores its lamp as "newmtl light / Ka 20 20 20"). Ka elsewhere is an ambient
  // colour, which a GI renderer has no use for.
  if (!e.hasKe && nonZero(e.ka)) {
    std::string name = lower(m.name);
    if (name.find("light") != std::string::npos || name.find("emit") != std::string::npos)
      m.emission = e.ka;
  }
  // Blinn-Phong exponent -> GGX-style roughness (the usual sqrt(2 / (Ns + 2)) mapping).
  if (e.hasNs)
    m.roughness = std::clamp(std::sqrt(2.0f / (std::max(e.ns, 0.0f) + 2.0f)), 0.02f, 1.0f);
  return m;
}

// A vertex of a face, as the OBJ indices plus the key that decides sharing.
struct VertexKey {
  long v, vt, vn;
  long long share;  // smoothing group (negative) or face number: vertices share only within it
  bool operator==(const VertexKey& o) const {
    return v == o.v && vt == o.vt && vn == o.vn && share == o.share;
  }
};
struct VertexKeyHash {
  size_t operator()(const VertexKey& k) const {
    size_t h = std::hash<long>()(k.v);
    h = h * 1000003u ^ std::hash<long>()(k.vt);
    h = h * 1000003u ^ std::hash<long>()(k.vn);
    return h * 1000003u ^ std::hash<long long>()(k.share);
  }
};

struct Group {
  Mesh mesh;
  std::unordered_map<VertexKey, uint32_t, VertexKeyHash> vertexOf;
};

class ObjReader {
 public:
  explicit ObjReader(const std::string& path) : path_(path) {}

  MeshFileData read() {
    std::string text = readTextFile(path_);
    forEachLine(text, [&](std::string_view line, size_t lineNo) {
      parseLine(line, LineError(path_, lineNo));
    });
    for (Group& g : groups_)
      if (!g.mesh.indices.empty()) data_.meshes.push_back(std::move(g.mesh));
    if (data_.meshes.empty())
      throw Error(ErrorKind::InvalidData, path_, "no faces (the file holds no usable geometry)");
    return std::move(data_);
  }

 private:
  void parseLine(std::string_view line, const LineError& err) {
    if (size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    auto tok = tokens(line);
    if (tok.empty()) return;
    const std::string_view kw = tok[0];
    if (kw == "v") {
      positions_.push_back(readVec<3>(tok, err));
    } else if (kw == "vt") {
      glm::vec2 t = readVec<2>(tok, err, 1);
      texcoords_.push_back({t.x, 1.0f - t.y});  // OBJ's v goes up; ours goes down the image
    } else if (kw == "vn") {
      normals_.push_back(readVec<3>(tok, err));
    } else if (kw == "f") {
      parseFace(tok, err);
    } else if (kw == "usemtl") {
      currentMaterial_ = materialIndex(restOfLine(line, "usemtl"));
    } else if (kw == "mtllib") {
      // A broken library names the OBJ and its line as well as the library.
      for (size_t i = 1; i < tok.size(); ++i) {
        try {
          loadMtl(std::string(tok[i]));
        } catch (const Error& e) {
          err.fail(e.kind(), "mtllib " + std::string(tok[i]) + ": " + e.what());
        }
      }
    } else if (kw == "s") {
      long group = 0;
      smoothing_ = (tok.size() >= 2 && parseInt(tok[1], group)) ? group : 0;  // "s off" -> 0
    }
  }

  // Resolves an OBJ index (1-based, or negative relative to the end) against `count` items.
  long resolve(std::string_view s, size_t count, const char* what, const LineError& err) {
    long i = 0;
    if (!parseInt(s, i))
      err.fail(ErrorKind::Parse, "bad " + std::string(what) + " index '" + std::string(s) + "'");
    long resolved = i > 0 ? i - 1 : static_cast<long>(count) + i;
    if (i == 0 || resolved < 0 || resolved >= static_cast<long>(count))
      err.fail(ErrorKind::IndexOutOfRange, std::string(what) + " index " + std::to_string(i) +
                                               " is out of range (" + std::to_string(count) +
                                               " defined so far)");
    return resolved;
  }

  void parseFace(const std::vector<std::string_view>& tok, const LineError& err) {
    if (tok.size() < 4) err.fail(ErrorKind::Parse, "a face needs at least 3 vertices");
    ++faceNumber_;
    Group& group = currentGroup();
    std::vector<uint32_t> corners;
    corners.reserve(tok.size() - 1);
    for (size_t c = 1; c < tok.size(); ++c) {
      std::string_view ref = tok[c];
      size_t s1 = ref.find('/');
      size_t s2 = s1 == std::string_view::npos ? s1 : ref.find('/', s1 + 1);
      VertexKey key{resolve(ref.substr(0, s1), positions_.size(), "vertex", err), -1, -1, 0};
      if (s1 != std::string_view::npos) {
        std::string_view vt = ref.substr(s1 + 1, s2 == std::string_view::npos ? s2 : s2 - s1 - 1);
        if (!vt.empty()) key.vt = resolve(vt, texcoords_.size(), "texture coordinate", err);
        if (s2 != std::string_view::npos)
          key.vn = resolve(ref.substr(s2 + 1), normals_.size(), "normal", err);
      }
      // Without a normal the vertex is shared only inside its smoothing group, or inside
      // this face when smoothing is off (flat shading).
      if (key.vn < 0) key.share = smoothing_ != 0 ? -smoothing_ : faceNumber_;
      auto [it, inserted] =
          group.vertexOf.emplace(key, static_cast<uint32_t>(group.mesh.vertices.size()));
      if (inserted) {
        Vertex v;
        v.position = positions_[key.v];
        v.normal = key.vn >= 0 ? normals_[key.vn] : glm::vec3(0.0f);  // 0: processMesh computes
        if (key.vt >= 0) v.uv = texcoords_[key.vt];
        group.mesh.vertices.push_back(v);
      }
      corners.push_back(it->second);
    }
    for (size_t i = 1; i + 1 < corners.size(); ++i)  // fan triangulation
      group.mesh.indices.insert(group.mesh.indices.end(), {corners[0], corners[i], corners[i + 1]});
  }

  Group& currentGroup() {
    if (currentMaterial_ < 0) currentMaterial_ = materialIndex("");  // faces before usemtl
    while (groups_.size() <= static_cast<size_t>(currentMaterial_)) {
      groups_.emplace_back();
      groups_.back().mesh.material = static_cast<uint32_t>(groups_.size() - 1);
      groups_.back().mesh.name = data_.materials[groups_.size() - 1].name;
    }
    return groups_[currentMaterial_];
  }

  // Index of the scene material for an MTL name, created on first use.
  int materialIndex(const std::string& name) {
    for (size_t i = 0; i < data_.materials.size(); ++i)
      if (data_.materials[i].name == (name.empty() ? "default" : name)) return static_cast<int>(i);
    Material m;
    m.name = name.empty() ? "default" : name;
    if (auto it = mtl_.find(name); it != mtl_.end()) {
      m = toMaterial(it->second);
      if (!it->second.mapKd.empty()) m.baseColorTexture = loadTexture(it->second.mapKd);
    } else if (!name.empty()) {
      data_.warnings.push_back(path_ + ": material '" + name +
                               "' is not defined in any mtllib; using a grey default");
    }
    data_.materials.push_back(m);
    return static_cast<int>(data_.materials.size()) - 1;
  }

  void loadMtl(const std::string& file) {
    fs::path mtlPath = fs::path(path_).parent_path() / file;
    std::error_code ec;
    if (!fs::exists(mtlPath, ec)) {
      data_.warnings.push_back(path_ + ": material library '" + mtlPath.string() +
                               "' not found; materials fall back to grey");
      return;
    }
    for (auto& [name, entry] : readMtl(mtlPath.string())) mtl_.emplace(name, std::move(entry));
  }

  int loadTexture(const std::string& file) {
    fs::path texPath = fs::path(path_).parent_path() / file;
    int w = 0, h = 0, n = 0;
    // Read through the checked reader (regular files only), then decode from memory.
    std::vector<unsigned char> bytes;
    std::string problem;
    unsigned char* pixels = nullptr;
    if (tryReadInputFile(texPath.string(), bytes, problem, "texture") &&
        bytes.size() <= size_t(std::numeric_limits<int>::max()))
      pixels = stbi_load_from_memory(bytes.data(), int(bytes.size()), &w, &h, &n, 4);
    else if (problem.empty())
      problem = "larger than 2 GiB";
    if (!pixels) {
      data_.warnings.push_back(path_ + ": texture '" + texPath.string() + "' could not be loaded" +
                               (problem.empty() ? "" : " (" + problem + ")") +
                               "; using the plain colour");
      return -1;
    }
    Texture t;
    t.name = file;
    t.width = w;
    t.height = h;
    t.rgba8.assign(pixels, pixels + static_cast<size_t>(w) * h * 4);
    stbi_image_free(pixels);
    data_.textures.push_back(std::move(t));
    return static_cast<int>(data_.textures.size()) - 1;
  }

  const std::string& path_;
  MeshFileData data_;
  std::vector<glm::vec3> positions_, normals_;
  std::vector<glm::vec2> texcoords_;
  std::unordered_map<std::string, MtlEntry> mtl_;
  std::vector<Group> groups_;  // one per material index
  int currentMaterial_ = -1;
  long smoothing_ = 0;
  long long faceNumber_ = 0;
};

}  // namespace

MeshFileData readObj(const std::string& path) {
  return ObjReader(path).read();
}

}  // namespace gi::detail
