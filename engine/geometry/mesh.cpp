// Mesh loading (OBJ by tinyobjloader, STL and PLY by assimp) and the inside test of closed
// triangle surfaces.
//
// The one tinyobjloader implementation unit of the project. Coordinates are parsed in single
// precision (the ABI of Debian's libtinyobjloader; STL stores floats), then widened to double
// and scaled.
#define TINYOBJLOADER_IMPLEMENTATION
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <tiny_obj_loader.h>

#include <assimp/Importer.hpp>

#include <array>
#include <cctype>
#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "engine/geometry/mesh.h"
#include "engine/geometry/mesh_query.h"

namespace phyxel {
namespace {

[[noreturn]] void fail(const std::filesystem::path& path, const std::string& message) {
  throw std::runtime_error(path.string() + ": " + message);
}

// The statements of an OBJ file that tinyobjloader gets: only those a mesh shape uses
// (vertices, texture and normal coordinates that faces may name, faces, object and group
// names). Every other line (skin weights `vw`, tags, materials, lines, points, smoothing
// groups, comments) becomes an empty line, so tinyobjloader's line numbers stay right.
// Fuzzing found undefined behaviour in tinyobjloader's reading of `vw` lines (a weight's
// joint id converted to int unchecked) and of numbers whose exponent has 10 digits (an int
// overflow); the first never reaches it now, the second is refused here with the line.
std::string geometry_statements(const std::filesystem::path& path, const std::string& text) {
  std::string out;
  out.reserve(text.size());
  size_t line_number = 0;
  for (size_t begin = 0; begin < text.size();) {
    // Lines end at "\n", "\r\n" or a lone "\r", as tinyobjloader reads them.
    size_t end = text.find_first_of("\r\n", begin);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(begin, end - begin);
    begin = end < text.size() && text[end] == '\r' && end + 1 < text.size() && text[end + 1] == '\n'
                ? end + 2
                : end + 1;
    ++line_number;
    const size_t start = line.find_first_not_of(" \t");
    const size_t stop = start == std::string::npos ? start : line.find_first_of(" \t", start);
    const std::string keyword =
        start == std::string::npos
            ? ""
            : line.substr(start, stop == std::string::npos ? stop : stop - start);
    const bool numbers = keyword == "v" || keyword == "vt" || keyword == "vn";
    if (numbers || keyword == "f" || keyword == "o" || keyword == "g") {
      if (numbers)
        for (size_t e = line.find_first_of("eE"); e != std::string::npos;
             e = line.find_first_of("eE", e + 1)) {
          size_t digit = e + 1;
          if (digit < line.size() && (line[digit] == '+' || line[digit] == '-')) ++digit;
          while (digit < line.size() && line[digit] == '0') ++digit;
          size_t digits = 0;
          while (digit + digits < line.size() &&
                 std::isdigit(static_cast<unsigned char>(line[digit + digits])))
            ++digits;
          if (digits > 9)
            fail(path, "line " + std::to_string(line_number) +
                           ": a number's exponent has more than 9 digits; write coordinates as "
                           "ordinary decimal numbers");
        }
      out += line;
    }
    out += '\n';
  }
  return out;
}

// tinyobjloader's messages are newline-separated; ours are one line.
std::string one_line(const std::string& text) {
  std::string out;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    while (!line.empty() && (line.back() == '\r' || line.back() == '.' || line.back() == ' '))
      line.pop_back();
    if (line.empty()) continue;
    if (!out.empty()) out += "; ";
    out += line;
  }
  return out;
}

struct EdgeUse {
  int count = 0;    // triangles using the edge
  int forward = 0;  // of those, how many run from the lower to the higher vertex index
};

// Every edge must be shared by exactly two triangles that run it in opposite directions.
void check_closed(const std::filesystem::path& path, const std::vector<Eigen::Vector3i>& tris,
                  const std::vector<int>& file_index, const std::string& vertex_word) {
  std::unordered_map<uint64_t, EdgeUse> edges;
  edges.reserve(tris.size() * 2);
  for (const Eigen::Vector3i& t : tris) {
    for (int k = 0; k < 3; ++k) {
      const int a = t[k], b = t[(k + 1) % 3];
      EdgeUse& use = edges[edge_key(a, b)];
      ++use.count;
      if (a < b) ++use.forward;
    }
  }
  size_t open = 0, flipped = 0;
  uint64_t first_open = 0, first_flipped = 0;
  int open_count = 0;
  for (const auto& [key, use] : edges) {
    if (use.count != 2) {
      if (open++ == 0 || key < first_open) {
        first_open = key;
        open_count = use.count;
      }
    } else if (use.forward != 1) {
      if (flipped++ == 0 || key < first_flipped) first_flipped = key;
    }
  }
  auto vertices = [&](uint64_t key) {
    return vertex_word + " " + std::to_string(file_index[key >> 32]) + " and " +
           std::to_string(file_index[key & 0xffffffffu]);
  };
  if (open > 0)
    fail(path, "the surface is not closed: " + std::to_string(open) +
                   " edges are not shared by exactly two triangles (first: the edge between " +
                   vertices(first_open) + ", used by " + std::to_string(open_count) +
                   "); a mesh shape must be a closed (watertight) surface: check every edge is "
                   "shared by exactly two triangles");
  if (flipped > 0)
    fail(path, "the triangles are not consistently oriented: " + std::to_string(flipped) +
                   " edges run the same way in both of their triangles (first: the edge between " +
                   vertices(first_flipped) +
                   "); re-export the surface with consistent face winding (normals all outward)");
}

void check_scale(const std::filesystem::path& path, double scale) {
  if (!(std::isfinite(scale) && scale > 0))
    fail(path, "the mesh scale must be a positive number (got " + std::to_string(scale) + ")");
}

// Triangles as a file stores them: positions per file vertex, faces as indices into them.
struct RawSurface {
  std::vector<std::array<float, 3>> positions;
  std::vector<std::array<int, 3>> faces;
  std::string vertex_word;  // "OBJ vertices": how messages name the file's vertices
};

// Welds vertices at identical positions (exporters that repeat positions per face, and STL,
// which always does, still give a connected surface), leaves out collapsed faces, checks that
// the surface is closed and bounds a volume, and turns it outward.
TriangleMesh closed_mesh(const std::filesystem::path& path, const RawSurface& raw, double scale) {
  TriangleMesh mesh;
  std::vector<int> file_index;  // 1-based number in the file, for messages
  std::map<std::array<float, 3>, int> welded;
  std::vector<int> remap(raw.positions.size(), -1);
  auto vertex_id = [&](int v) {
    if (remap[v] < 0) {
      const std::array<float, 3>& key = raw.positions[v];
      auto [it, inserted] = welded.emplace(key, static_cast<int>(mesh.vertices.size()));
      if (inserted) {
        mesh.vertices.push_back(scale * Vec3(key[0], key[1], key[2]));
        file_index.push_back(v + 1);
      }
      remap[v] = it->second;
    }
    return remap[v];
  };
  for (const auto& f : raw.faces) {
    const Eigen::Vector3i t(vertex_id(f[0]), vertex_id(f[1]), vertex_id(f[2]));
    // A face that collapses onto an edge or a point bounds no area and is left out.
    if (t[0] != t[1] && t[1] != t[2] && t[2] != t[0]) mesh.triangles.push_back(t);
  }
  if (mesh.triangles.empty())
    fail(path,
         "the file has no triangle or polygon faces; a mesh shape needs a closed "
         "triangle surface");
  check_closed(path, mesh.triangles, file_index, raw.vertex_word);

  for (const Vec3& v : mesh.vertices) mesh.bounds.extend(v);
  double volume = 0;
  for (const Eigen::Vector3i& t : mesh.triangles)
    volume += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]])) / 6;
  const double diagonal = mesh.bounds.diagonal().norm();
  if (!(std::abs(volume) > 1e-12 * diagonal * diagonal * diagonal))
    fail(path, "the closed surface encloses no volume; a mesh shape must bound a solid");
  // Inward-facing surfaces (clockwise faces) are common in exported files: turn them outward,
  // which the winding-number inside test needs.
  if (volume < 0)
    for (Eigen::Vector3i& t : mesh.triangles) std::swap(t[1], t[2]);
  return mesh;
}

}  // namespace

bool TriangleMesh::contains(const Vec3& p) const {
  return winding_number_direct(*this, p) > 0.5;
}

TriangleMesh load_obj_mesh(const std::filesystem::path& path, double scale) {
  check_scale(path, scale);
  std::error_code ec;
  std::ifstream in;
  if (std::filesystem::is_regular_file(path, ec)) in.open(path, std::ios::binary);
  if (!in.is_open()) throw std::runtime_error("cannot open " + path.string() + ": check the path");
  return parse_obj_mesh({std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()},
                        path, scale);
}

TriangleMesh parse_obj_mesh(const std::string& text, const std::filesystem::path& path,
                            double scale) {
  check_scale(path, scale);
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  // No material reader: `mtllib` lines are ignored, only the geometry matters here.
  std::istringstream geometry(geometry_statements(path, text));
  const bool ok = tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &geometry, nullptr,
                                   /*triangulate=*/true, /*default_vcols_fallback=*/false);
  if (!ok || !err.empty()) fail(path, "cannot parse the OBJ file: " + one_line(err));
  // tinyobjloader drops faces with bad vertex indices with only a warning; a dropped face
  // would surface later as an open mesh, so report the real cause.
  if (warn.find("Vertex indices out of bounds") != std::string::npos ||
      warn.find("invalid vertex index") != std::string::npos)
    fail(path, "cannot parse the OBJ file: " + one_line(warn) +
                   "; every face must refer to vertices defined in the file");

  RawSurface raw;
  raw.vertex_word = "OBJ vertices";
  for (size_t v = 0; v + 2 < attrib.vertices.size(); v += 3)
    raw.positions.push_back({attrib.vertices[v], attrib.vertices[v + 1], attrib.vertices[v + 2]});
  for (const tinyobj::shape_t& shape : shapes) {
    size_t offset = 0;
    for (const unsigned char corners : shape.mesh.num_face_vertices) {
      if (corners == 3) {
        std::array<int, 3> t;
        for (int k = 0; k < 3; ++k) {
          const int v = shape.mesh.indices[offset + k].vertex_index;
          if (v < 0 || static_cast<size_t>(v) >= raw.positions.size())
            fail(path, "a face of '" + shape.name + "' refers to vertex " + std::to_string(v + 1) +
                           ", but the file defines " + std::to_string(raw.positions.size()) +
                           " vertices; every face must refer to vertices defined in the file");
          t[k] = v;
        }
        raw.faces.push_back(t);
      }
      offset += corners;
    }
  }
  return closed_mesh(path, raw, scale);
}

TriangleMesh load_assimp_mesh(const std::filesystem::path& path, double scale,
                              const std::string& format) {
  check_scale(path, scale);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw std::runtime_error("cannot open " + path.string() + ": check the path");
  Assimp::Importer importer;
  // Points and lines bound nothing: they are dropped, the faces triangulated. Vertices are
  // welded below, as for OBJ files, so that messages can name them.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene =
      importer.ReadFile(path.string(), aiProcess_Triangulate | aiProcess_SortByPType);
  if (!scene)
    fail(path, "cannot parse the " + format + " file: " + one_line(importer.GetErrorString()));
  RawSurface raw;
  raw.vertex_word = format + " vertices";
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    const int base = static_cast<int>(raw.positions.size());
    for (unsigned v = 0; v < mesh->mNumVertices; ++v)
      raw.positions.push_back(
          {float(mesh->mVertices[v].x), float(mesh->mVertices[v].y), float(mesh->mVertices[v].z)});
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;
      std::array<int, 3> t;
      for (int k = 0; k < 3; ++k) {
        if (face.mIndices[k] >= mesh->mNumVertices)
          fail(path, "a face refers to vertex " + std::to_string(face.mIndices[k] + 1) +
                         " of a mesh of " + std::to_string(mesh->mNumVertices) + " vertices");
        t[k] = base + static_cast<int>(face.mIndices[k]);
      }
      raw.faces.push_back(t);
    }
  }
  return closed_mesh(path, raw, scale);
}

TriangleMesh load_mesh(const std::filesystem::path& path, double scale) {
  std::string ext = path.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".obj") return load_obj_mesh(path, scale);
  if (ext == ".stl") return load_assimp_mesh(path, scale, "STL");
  if (ext == ".ply") return load_assimp_mesh(path, scale, "PLY");
  fail(path, "unsupported mesh format \"" + ext +
                 "\"; use a closed surface in OBJ (.obj), STL "
                 "(.stl, binary or ASCII) or PLY (.ply)");
}

}  // namespace phyxel
