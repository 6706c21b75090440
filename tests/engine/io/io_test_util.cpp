#include "io_test_util.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace remesh::test {

namespace {

template <class T>
void put(std::string& out, T v, bool big) {
  unsigned char raw[sizeof(T)];
  std::memcpy(raw, &v, sizeof(T));
  if (big)
    for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(raw[i], raw[sizeof(T) - 1 - i]);
  out.append(reinterpret_cast<const char*>(raw), sizeof(T));
}


std::string ply_header(const PolygonSoup& soup, const char* format) {
  return std::string("ply\nformat ") + format +
         " 1.0\ncomment test file\nobj_info extra\nelement vertex " + std::to_string(soup.points.size()) +
         "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty double confidence\n"
         "element face " + std::to_string(soup.offsets.size() - 1) +
         "\nproperty uchar flags\nproperty list uchar int vertex_indices\nproperty float quality\n"
         "element material 1\nproperty list ushort uchar name\nend_header\n";
}

}  // namespace

std::string base64(const std::string& in) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  std::size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    unsigned v = (unsigned char)in[i] << 16 | (unsigned char)in[i + 1] << 8 | (unsigned char)in[i + 2];
    out += {t[v >> 18], t[(v >> 12) & 63], t[(v >> 6) & 63], t[v & 63]};
  }
  if (i + 1 == in.size()) {
    unsigned v = (unsigned char)in[i] << 16;
    out += {t[v >> 18], t[(v >> 12) & 63], '=', '='};
  } else if (i + 2 == in.size()) {
    unsigned v = (unsigned char)in[i] << 16 | (unsigned char)in[i + 1] << 8;
    out += {t[v >> 18], t[(v >> 12) & 63], t[(v >> 6) & 63], '='};
  }
  return out;
}

PolygonSoup make_soup(const std::vector<Vec3>& points, const std::vector<std::vector<std::uint32_t>>& faces) {
  PolygonSoup s;
  s.points = points;
  for (const auto& f : faces) {
    s.indices.insert(s.indices.end(), f.begin(), f.end());
    s.offsets.push_back(static_cast<std::uint32_t>(s.indices.size()));
  }
  return s;
}

std::string write_ply_ascii(const PolygonSoup& soup) {
  std::string out = ply_header(soup, "ascii");
  char buf[128];
  for (const Vec3& p : soup.points) {
    std::snprintf(buf, sizeof buf, "%.9g %.9g %.9g 7 0.5\n", p[0], p[1], p[2]);
    out += buf;
  }
  for (std::size_t f = 0; f + 1 < soup.offsets.size(); ++f) {
    out += "0 ";  // (two appends: GCC 12 warns falsely about "literal" + std::string)
    out += std::to_string(soup.offsets[f + 1] - soup.offsets[f]);
    for (auto k = soup.offsets[f]; k < soup.offsets[f + 1]; ++k) {
      out += ' ';
      out += std::to_string(soup.indices[k]);
    }
    out += " 1.5\n";
  }
  out += "3 65 66 67\n";
  return out;
}

std::string write_ply_big_endian(const PolygonSoup& soup) {
  std::string out = ply_header(soup, "binary_big_endian");
  for (const Vec3& p : soup.points) {
    for (int k = 0; k < 3; ++k) put<float>(out, static_cast<float>(p[k]), true);
    put<std::uint8_t>(out, 7, true);
    put<double>(out, 0.5, true);
  }
  for (std::size_t f = 0; f + 1 < soup.offsets.size(); ++f) {
    put<std::uint8_t>(out, 0, true);
    put<std::uint8_t>(out, static_cast<std::uint8_t>(soup.offsets[f + 1] - soup.offsets[f]), true);
    for (auto k = soup.offsets[f]; k < soup.offsets[f + 1]; ++k) put<std::int32_t>(out, static_cast<std::int32_t>(soup.indices[k]), true);
    put<float>(out, 1.5f, true);
  }
  put<std::uint16_t>(out, 3, true);
  out += "ABC";
  return out;
}

std::string write_off_binary(const PolygonSoup& soup) {
  std::string out = "OFF BINARY\n";
  put<std::int32_t>(out, static_cast<std::int32_t>(soup.points.size()), true);
  put<std::int32_t>(out, static_cast<std::int32_t>(soup.offsets.size() - 1), true);
  put<std::int32_t>(out, 0, true);
  for (const Vec3& p : soup.points)
    for (int k = 0; k < 3; ++k) put<float>(out, static_cast<float>(p[k]), true);
  for (std::size_t f = 0; f + 1 < soup.offsets.size(); ++f) {
    put<std::int32_t>(out, static_cast<std::int32_t>(soup.offsets[f + 1] - soup.offsets[f]), true);
    for (auto k = soup.offsets[f]; k < soup.offsets[f + 1]; ++k) put<std::int32_t>(out, static_cast<std::int32_t>(soup.indices[k]), true);
    put<std::int32_t>(out, f % 2 ? 3 : 0, true);  // some faces carry an RGB colour
    if (f % 2)
      for (int k = 0; k < 3; ++k) put<float>(out, 0.25f, true);
  }
  return out;
}

std::string write_stl_ascii(const PolygonSoup& soup) {
  std::string out = "solid test\n";
  char buf[160];
  for (std::size_t f = 0; f + 1 < soup.offsets.size(); ++f) {
    const auto b = soup.offsets[f];
    for (auto k = b + 1; k + 1 < soup.offsets[f + 1]; ++k) {
      out += "  facet normal 0 0 0\n    outer loop\n";
      for (auto i : {soup.indices[b], soup.indices[k], soup.indices[k + 1]}) {
        const Vec3& p = soup.points[i];
        std::snprintf(buf, sizeof buf, "      vertex %.17g %.17g %.17g\n", p[0], p[1], p[2]);
        out += buf;
      }
      out += "    endloop\n  endfacet\n";
    }
  }
  return out + "endsolid test\n";
}

std::string write_gltf_data_uri(const PolygonSoup& soup, const std::string& uri) {
  std::string bin;
  std::vector<std::uint32_t> tris;
  for (std::size_t f = 0; f + 1 < soup.offsets.size(); ++f)
    for (auto k = soup.offsets[f] + 1; k + 1 < soup.offsets[f + 1]; ++k)
      tris.insert(tris.end(), {soup.indices[soup.offsets[f]], soup.indices[k], soup.indices[k + 1]});
  for (const Vec3& p : soup.points)
    for (int k = 0; k < 3; ++k) put<float>(bin, static_cast<float>(p[k]), false);
  const std::size_t idx_offset = bin.size();
  for (auto i : tris) put<std::uint16_t>(bin, static_cast<std::uint16_t>(i), false);
  while (bin.size() % 4) bin += '\0';
  const std::string n = std::to_string(soup.points.size());
  return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
         R"("meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
         R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" + n +
         R"(,"type":"VEC3"},{"bufferView":1,"componentType":5123,"count":)" + std::to_string(tris.size()) +
         R"(,"type":"SCALAR"}],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":)" +
         std::to_string(idx_offset) + R"(},{"buffer":0,"byteOffset":)" + std::to_string(idx_offset) +
         R"(,"byteLength":)" + std::to_string(2 * tris.size()) + R"(}],"buffers":[{"byteLength":)" +
         std::to_string(bin.size()) + R"(,"uri":")" +
         (uri.empty() ? "data:application/octet-stream;base64," + base64(bin) : uri) + R"("}]})";
}

std::vector<SampleFile> sample_files(const PolygonSoup& soup) {
  return {
      {"obj", Format::Obj, write_mesh(soup, Format::Obj)},
      {"off_ascii", Format::Off, write_mesh(soup, Format::Off)},
      {"off_binary", Format::Off, write_off_binary(soup)},
      {"ply_ascii", Format::Ply, write_ply_ascii(soup)},
      {"ply_le", Format::Ply, write_mesh(soup, Format::Ply)},
      {"ply_be", Format::Ply, write_ply_big_endian(soup)},
      {"stl_ascii", Format::Stl, write_stl_ascii(soup)},
      {"stl_binary", Format::Stl, write_mesh(soup, Format::Stl)},
      {"gltf", Format::Gltf, write_gltf_data_uri(soup)},
      {"gltf_written", Format::Gltf, write_mesh(soup, Format::Gltf)},
      {"glb", Format::Glb, write_mesh(soup, Format::Glb)},
  };
}

bool zero_area(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 e1 = b - a, e2 = c - a, e3 = c - b;
  const double longest = std::max({e1.norm(), e2.norm(), e3.norm()});
  return !(OpenMesh::cross(e1 / longest, e2 / longest).norm() > 1e-12);
}

std::string check_loaded(const TriMesh& mesh) {
  if (mesh.n_faces() == 0) return "no faces";
  for (auto v : mesh.vertices()) {
    if (mesh.status(v).deleted()) return "deleted vertex left";
    const Vec3& p = mesh.point(v);
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) return "non-finite point";
    if (!mesh.is_manifold(v)) return "non-manifold vertex " + std::to_string(v.idx());
    if (mesh.valence(v) == 0) return "isolated vertex " + std::to_string(v.idx());
  }
  for (auto f : mesh.faces()) {
    if (mesh.valence(f) != 3) return "non-triangle face";
    auto h = mesh.halfedge_handle(f);
    auto a = mesh.from_vertex_handle(h), b = mesh.to_vertex_handle(h), c = mesh.to_vertex_handle(mesh.next_halfedge_handle(h));
    if (a == b || b == c || a == c) return "face with a repeated vertex";
    if (zero_area(mesh.point(a), mesh.point(b), mesh.point(c))) return "zero-area face " + std::to_string(f.idx());
  }
  for (auto e : mesh.edges())
    if (mesh.is_boundary(mesh.halfedge_handle(e, 0)) && mesh.is_boundary(mesh.halfedge_handle(e, 1)))
      return "edge without faces";
  return "";
}

void check_same_mesh(const LoadedMesh& got, const LoadedMesh& want) {
  REQUIRE(got.mesh.n_vertices() == want.mesh.n_vertices());
  REQUIRE(got.mesh.n_faces() == want.mesh.n_faces());
  for (auto v : want.mesh.vertices()) CHECK(got.mesh.point(v) == want.mesh.point(v));
  for (auto f : want.mesh.faces()) {
    std::vector<int> a, b;
    for (auto v : got.mesh.fv_range(f)) a.push_back(v.idx());
    for (auto v : want.mesh.fv_range(f)) b.push_back(v.idx());
    CHECK(a == b);
  }
}

}  // namespace remesh::test
