// PLY reader: OpenMesh's PLY reader parses the file (ascii and binary), feeding a checking
// importer that records the faces with their original vertex indices.
//
// Some things are checked here because OpenMesh does not: its header parser never returns on
// a header that ends early (it loops at end of file), and its ASCII reader does not notice a
// body that ends early or holds garbage, so header and ASCII body are validated first; it also
// silently skips faces with out-of-range indices, which we report as IndexOutOfRange.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

// MeshIO.hh must come before the mesh type so that the readers are registered.
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/IO/importer/ImporterT.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include "gi/errors.h"
#include "gi/input_file.h"
#include "scene_io_util.h"

namespace gi::detail {
namespace {

namespace fs = std::filesystem;
using OmMesh = OpenMesh::TriMesh_ArrayKernelT<>;

struct PlyProperty {
  bool list = false;
  size_t size = 0;       // bytes of a scalar, or of a list's items
  size_t countSize = 0;  // bytes of a list's count
};
struct PlyElement {
  std::string name;
  size_t count = 0;
  std::vector<PlyProperty> properties;
};
struct PlyHeader {
  bool ascii = true;
  size_t headerBytes = 0;
  size_t vertexCount = 0, faceCount = 0;
  std::vector<PlyElement> elements;
};

size_t scalarSize(const std::string& type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "float" || type == "int32" || type == "uint32" ||
      type == "float32")
    return 4;
  if (type == "double" || type == "float64") return 8;
  return 0;
}

// Checks the header line by line (keywords, types, counts), so that a truncated header never
// reaches OpenMesh.
PlyHeader readHeader(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  auto fail = [&](size_t line, const std::string& what) {
    throw Error(ErrorKind::Parse, path, "PLY header line " + std::to_string(line) + ": " + what);
  };
  PlyHeader h;
  std::string line;
  size_t lineNo = 0;
  bool ended = false, sawFormat = false;
  while (!ended && std::getline(in, line)) {
    ++lineNo;
    h.headerBytes += line.size() + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string kw;
    words >> kw;
    if (lineNo == 1) {
      if (kw != "ply") fail(1, "not a PLY file (first line must be 'ply')");
      continue;
    }
    // Every line has exactly its tokens: OpenMesh's own header reader loops forever on some
    // malformed lines (fuzzing found "format binary_little_endian format ..."; regression input
    // in tests/fuzz/regressions/ply).
    auto noMoreTokens = [&](const char* what) {
      std::string extra;
      if (words >> extra) fail(lineNo, std::string(what) + ": unexpected '" + extra + "'");
    };
    if (kw == "format") {
      std::string fmt, version;
      words >> fmt >> version;
      if (fmt != "ascii" && fmt != "binary_little_endian" && fmt != "binary_big_endian")
        fail(lineNo, "unknown format '" + fmt + "'");
      if (version != "1.0") fail(lineNo, "format version must be 1.0, got '" + version + "'");
      noMoreTokens("format line");
      if (sawFormat || !h.elements.empty()) fail(lineNo, "format line repeated or too late");
      h.ascii = fmt == "ascii";
      sawFormat = true;
    } else if (kw == "element") {
      PlyElement e;
      long long count = -1;
      words >> e.name >> count;
      if (e.name.empty() || !words || count < 0) fail(lineNo, "malformed element line");
      noMoreTokens("element line");
      e.count = static_cast<size_t>(count);
      if (e.name == "vertex") h.vertexCount = e.count;
      if (e.name == "face") h.faceCount = e.count;
      h.elements.push_back(std::move(e));
    } else if (kw == "property") {
      if (h.elements.empty()) fail(lineNo, "property before any element");
      std::string type, countType, itemType, name;
      words >> type;
      PlyProperty prop;
      if (type == "list") {
        words >> countType >> itemType >> name;
        prop = {true, scalarSize(itemType), scalarSize(countType)};
        if (!prop.size || !prop.countSize || name.empty()) fail(lineNo, "malformed list property");
      } else {
        words >> name;
        prop = {false, scalarSize(type), 0};
        if (!prop.size || name.empty()) fail(lineNo, "unknown property type '" + type + "'");
      }
      noMoreTokens("property line");
      h.elements.back().properties.push_back(prop);
    } else if (kw == "end_header") {
      noMoreTokens("end_header line");
      ended = true;
    } else if (kw != "comment" && kw != "obj_info" && !kw.empty()) {
      fail(lineNo, "unknown keyword '" + kw + "'");
    }
  }
  if (lineNo == 0) throw Error(ErrorKind::EmptyFile, path, "file is empty");
  if (!ended) throw Error(ErrorKind::Parse, path, "PLY header has no end_header line");
  if (!sawFormat) throw Error(ErrorKind::Parse, path, "PLY header has no format line");
  if (h.faceCount == 0)
    throw Error(ErrorKind::InvalidData, path,
                "PLY has no faces (a point cloud cannot be rendered)");
  return h;
}

// Binary: the body must hold at least the fixed-size part of every element (so that absurd
// counts fail before OpenMesh reserves memory for them). OpenMesh itself reports a binary
// body that ends early.
void checkBinaryBodySize(const std::string& path, const PlyHeader& h) {
  std::error_code ec;
  const uintmax_t size = fs::file_size(path, ec);
  if (ec) return;
  const uintmax_t body = size - std::min<uintmax_t>(size, h.headerBytes);
  uintmax_t needed = 0;
  for (const PlyElement& e : h.elements) {
    uintmax_t perElement = 0;
    for (const PlyProperty& p : e.properties) perElement += p.list ? p.countSize : p.size;
    if (perElement && e.count > (body - std::min(body, needed)) / perElement) {
      throw Error(ErrorKind::Parse, path,
                  "file is shorter than its header declares (" + std::to_string(e.count) + " '" +
                      e.name + "' elements): truncated?");
    }
    needed += perElement * e.count;
  }
}

// ASCII: OpenMesh reads a body that ends early without noticing (repeating the last face), so
// walk the tokens first: every element must be complete and every value a plain number.
void checkAsciiBody(const std::string& path, const PlyHeader& h) {
  std::ifstream in(path, std::ios::binary);
  in.seekg(static_cast<std::streamoff>(h.headerBytes));
  std::string token;
  auto next = [&](const PlyElement& e, size_t index, bool integer) -> double {
    if (!(in >> token))
      throw Error(ErrorKind::Parse, path,
                  "file ends early, in " + e.name + " " + std::to_string(index) + " of " +
                      std::to_string(e.count));
    double value = 0;
    const char* begin = token.data() + (token[0] == '+' ? 1 : 0);
    auto [end, ec] = std::from_chars(begin, token.data() + token.size(), value);
    const bool plain = token.find_first_of("nNiI") == std::string::npos;  // no nan/inf
    if (ec != std::errc() || end != token.data() + token.size() || !plain ||
        (integer && value != std::floor(value)))
      throw Error(ErrorKind::Parse, path,
                  "'" + token + "' in " + e.name + " " + std::to_string(index) +
                      " is not a valid " + (integer ? "integer" : "number"));
    return value;
  };
  for (const PlyElement& e : h.elements) {
    for (size_t i = 0; i < e.count; ++i) {
      for (const PlyProperty& p : e.properties) {
        if (!p.list) {
          next(e, i, false);
          continue;
        }
        const double n = next(e, i, true);
        if (n < 0 || n > 1e6)
          throw Error(ErrorKind::Parse, path,
                      "bad list length in " + e.name + " " + std::to_string(i));
        for (size_t k = 0; k < static_cast<size_t>(n); ++k) next(e, i, false);
      }
    }
  }
}

// Records faces with their original indices while OpenMesh builds its own mesh. Faces with
// out-of-range indices are rejected (and reported afterwards), faces with repeated indices are
// dropped as degenerate.
class CheckingImporter : public OpenMesh::IO::ImporterT<OmMesh> {
 public:
  using Base = OpenMesh::IO::ImporterT<OmMesh>;
  explicit CheckingImporter(OmMesh& mesh) : Base(mesh) {}

  OpenMesh::VertexHandle add_vertex() override {
    ++vertices;
    return Base::add_vertex();
  }
  OpenMesh::VertexHandle add_vertex(const OpenMesh::Vec3f& p) override {
    ++vertices;
    return Base::add_vertex(p);
  }
  OpenMesh::FaceHandle add_face(const VHandles& corners) override {
    ++facesSeen;
    if (corners.size() < 3) {
      ++shortFaces;
      return OpenMesh::FaceHandle();
    }
    for (const auto& vh : corners)
      if (vh.idx() < 0 || static_cast<size_t>(vh.idx()) >= vertices) {
        if (badFace < 0) {
          badFace = static_cast<long long>(facesSeen) - 1;
          badIndex = vh.idx();
        }
        return OpenMesh::FaceHandle();
      }
    for (size_t i = 1; i + 1 < corners.size(); ++i)  // fan, like OpenMesh's own triangulation
      indices.insert(indices.end(), {static_cast<uint32_t>(corners[0].idx()),
                                     static_cast<uint32_t>(corners[i].idx()),
                                     static_cast<uint32_t>(corners[i + 1].idx())});
    // OpenMesh rejects repeated corners itself; such triangles are dropped by processMesh.
    return Base::add_face(corners);
  }

  size_t vertices = 0, facesSeen = 0, shortFaces = 0;
  long long badFace = -1;
  long long badIndex = 0;
  std::vector<uint32_t> indices;
};

}  // namespace

MeshFileData readPly(const std::string& path) {
  // Regular files only (OpenMesh would read a FIFO or /dev/zero forever), size-limited.
  if (checkInputFile(path) == 0) throw Error(ErrorKind::EmptyFile, path, "file is empty");
  const PlyHeader header = readHeader(path);
  if (header.ascii)
    checkAsciiBody(path, header);
  else
    checkBinaryBodySize(path, header);

  OmMesh om;
  om.request_vertex_normals();
  om.request_vertex_texcoords2D();
  CheckingImporter importer(om);
  OpenMesh::IO::Options opt;
  opt += OpenMesh::IO::Options::VertexNormal;
  opt += OpenMesh::IO::Options::VertexTexCoord;
  // OpenMesh reports problems on its own error stream; collect them for our message instead.
  std::ostringstream messages;
  const bool toCerr = ::omerr().disconnect(std::cerr);
  ::omerr().connect(messages);
  const bool ok = OpenMesh::IO::IOManager().read(path, importer, opt);
  ::omerr().disconnect(messages);
  if (toCerr) ::omerr().connect(std::cerr);
  std::string why = messages.str();
  while (!why.empty() && std::isspace(static_cast<unsigned char>(why.back()))) why.pop_back();

  if (importer.badFace >= 0)
    throw Error(ErrorKind::IndexOutOfRange, path,
                "face " + std::to_string(importer.badFace) + " uses vertex index " +
                    std::to_string(importer.badIndex) + " but there are only " +
                    std::to_string(importer.vertices) + " vertices");
  if (!ok)
    throw Error(ErrorKind::Parse, path,
                "OpenMesh cannot read it" + (why.empty() ? "" : ": " + why));
  if (importer.vertices < header.vertexCount || importer.facesSeen < header.faceCount)
    throw Error(ErrorKind::Parse, path,
                "file ends early: read " + std::to_string(importer.vertices) + " of " +
                    std::to_string(header.vertexCount) + " vertices and " +
                    std::to_string(importer.facesSeen) + " of " + std::to_string(header.faceCount) +
                    " faces");
  if (importer.shortFaces)
    throw Error(ErrorKind::Parse, path,
                std::to_string(importer.shortFaces) +
                    " faces have fewer than 3 vertices "
                    "(malformed face data)");

  MeshFileData data;
  Mesh mesh;
  mesh.name = fs::path(path).stem().string();
  mesh.vertices.resize(importer.vertices);
  for (size_t i = 0; i < importer.vertices; ++i) {
    const OpenMesh::VertexHandle vh(static_cast<int>(i));
    const auto& p = om.point(vh);
    Vertex& v = mesh.vertices[i];
    v.position = {p[0], p[1], p[2]};
    v.normal = glm::vec3(0.0f);  // 0: processMesh computes it
    if (opt.vertex_has_normal()) {
      const auto& n = om.normal(vh);
      v.normal = {n[0], n[1], n[2]};
    }
    if (opt.vertex_has_texcoord()) {
      const auto& t = om.texcoord2D(vh);
      v.uv = {t[0], 1.0f - t[1]};  // PLY's v goes up like OBJ's
    }
  }
  mesh.indices = std::move(importer.indices);
  mesh.material = 0;
  data.meshes.push_back(std::move(mesh));
  Material m;
  m.name = "default";
  data.materials.push_back(m);
  return data;
}

}  // namespace gi::detail
