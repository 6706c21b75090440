/// \file write_glb.cpp
/// glTF 2.0 writers: GLB, and text .gltf with its buffer in a data: URI (the document is built
/// here; tinygltf reads, and encodes the base64). One buffer with 4-byte aligned views: float32
/// POSITION (with min/max), UNSIGNED_INT triangle indices (faces fan-triangulated) and, when any
/// face is not a triangle, a LINES primitive sharing POSITION that carries every polygon edge once.

#include <algorithm>
#include <cstring>
#include <limits>
#include <utility>
#include <vector>

#include "io/parse_util.h"
#include "io/writers.h"

namespace remesh::io {

namespace {

std::vector<std::uint32_t> polygon_edges(const PolygonSoup& soup) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (std::size_t f = 0; f + 1 < soup.offsets.size(); ++f) {
    const std::uint32_t b = soup.offsets[f], e = soup.offsets[f + 1];
    for (std::uint32_t k = b; k < e; ++k) {
      std::uint32_t u = soup.indices[k], v = soup.indices[k + 1 < e ? k + 1 : b];
      edges.push_back({std::min(u, v), std::max(u, v)});
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::vector<std::uint32_t> out;
  out.reserve(2 * edges.size());
  for (auto [u, v] : edges) out.insert(out.end(), {u, v});
  return out;
}

std::string number(double v) {
  std::string s;
  append_number(s, v);
  return s;
}

/// The glTF JSON document of `soup` and its binary buffer (`bin`, unpadded). With `embed`, the
/// buffer is in the document as a base64 data: URI (text .gltf); without, it is the GLB's BIN chunk.
std::string gltf_document(const PolygonSoup& soup, std::string& bin, bool embed) {
  std::vector<std::uint32_t> tris;
  for_each_fan_triangle(soup, [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) { tris.insert(tris.end(), {a, b, c}); });
  bool polygons = false;
  for (std::size_t f = 0; f + 1 < soup.offsets.size(); ++f) polygons |= soup.offsets[f + 1] - soup.offsets[f] != 3;
  const std::vector<std::uint32_t> lines = polygons ? polygon_edges(soup) : std::vector<std::uint32_t>{};

  bin.clear();
  float lo[3] = {std::numeric_limits<float>::max(), std::numeric_limits<float>::max(), std::numeric_limits<float>::max()};
  float hi[3] = {-lo[0], -lo[1], -lo[2]};
  for (const Vec3& p : soup.points)
    for (int k = 0; k < 3; ++k) {
      const float v = static_cast<float>(p[k]);
      lo[k] = std::min(lo[k], v);
      hi[k] = std::max(hi[k], v);
      put_le<float>(bin, v);
    }
  const std::size_t tri_offset = bin.size();
  for (std::uint32_t i : tris) put_le<std::uint32_t>(bin, i);
  const std::size_t line_offset = bin.size();
  for (std::uint32_t i : lines) put_le<std::uint32_t>(bin, i);

  std::string json = R"({"asset":{"version":"2.0","generator":"remeshd"},"scene":0,)";
  if (soup.points.empty() || (tris.empty() && lines.empty())) {
    json += R"("scenes":[{"nodes":[]}]})";
  } else {
    const std::string n = std::to_string(soup.points.size());
    json += R"("scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],"meshes":[{"primitives":[)";
    std::string views = R"({"buffer":0,"byteOffset":0,"byteLength":)" + std::to_string(tri_offset) + R"(,"target":34962})";
    std::string accessors = R"({"bufferView":0,"componentType":5126,"count":)" + n + R"(,"type":"VEC3","min":[)" +
                            number(lo[0]) + "," + number(lo[1]) + "," + number(lo[2]) + R"(],"max":[)" + number(hi[0]) +
                            "," + number(hi[1]) + "," + number(hi[2]) + "]}";
    std::string prims;
    int next = 1;
    auto add = [&](std::size_t offset, std::size_t count, int mode) {
      const std::string id = std::to_string(next++);
      views += R"(,{"buffer":0,"byteOffset":)" + std::to_string(offset) + R"(,"byteLength":)" + std::to_string(4 * count) +
               R"(,"target":34963})";
      accessors += R"(,{"bufferView":)" + id + R"(,"componentType":5125,"count":)" + std::to_string(count) + R"(,"type":"SCALAR"})";
      if (!prims.empty()) prims += ',';
      prims += R"({"attributes":{"POSITION":0},"indices":)" + id + R"(,"mode":)" + std::to_string(mode) + "}";
    };
    if (!tris.empty()) add(tri_offset, tris.size(), 4);
    if (!lines.empty()) add(line_offset, lines.size(), 1);
    json += prims + R"(]}],"accessors":[)" + accessors + R"(],"bufferViews":[)" + views + "],";
    json += R"("buffers":[{"byteLength":)" + std::to_string(bin.size());
    if (embed) json += R"(,"uri":"data:application/octet-stream;base64,)" + base64(bin) + '"';
    json += "}]}";
  }
  return json;
}

}  // namespace

std::string write_gltf(const PolygonSoup& soup) {
  check_float32(soup, "glTF");
  std::string bin;
  return gltf_document(soup, bin, /*embed=*/true) + "\n";
}

std::string write_glb(const PolygonSoup& soup) {
  check_float32(soup, "GLB");
  std::string bin;
  std::string json = gltf_document(soup, bin, /*embed=*/false);
  while (json.size() % 4) json += ' ';
  while (bin.size() % 4) bin += '\0';
  const bool has_bin = !bin.empty();
  std::string out = "glTF";
  put_le<std::uint32_t>(out, 2);
  put_le<std::uint32_t>(out, static_cast<std::uint32_t>(12 + 8 + json.size() + (has_bin ? 8 + bin.size() : 0)));
  put_le<std::uint32_t>(out, static_cast<std::uint32_t>(json.size()));
  out += "JSON";
  out += json;
  if (has_bin) {
    put_le<std::uint32_t>(out, static_cast<std::uint32_t>(bin.size()));
    out.append("BIN\0", 4);
    out += bin;
  }
  return out;
}

}  // namespace remesh::io
