/// \file write_glb.cpp
/// glTF 2.0 writers: GLB, and text .gltf with its buffer in a base64 data: URI (built here;
/// tinygltf only reads). One buffer with 4-byte aligned views: float32 POSITION (with min/max),
/// UNSIGNED_INT triangle indices (faces fan-triangulated) and, when any face is not a triangle, a
/// LINES primitive sharing POSITION that carries every polygon edge once. Points without faces (the
/// dual of a mesh with no interior vertex) are a POINTS primitive; no points, a scene without nodes.

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
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

/// Base64 (RFC 4648, padded).
std::string base64(const std::string& in) {
  static constexpr char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  auto byte = [&](std::size_t i) { return static_cast<std::uint32_t>(static_cast<unsigned char>(in[i])); };
  std::size_t i = 0;
  for (; i + 3 <= in.size(); i += 3) {
    const std::uint32_t v = byte(i) << 16 | byte(i + 1) << 8 | byte(i + 2);
    out += {kDigits[v >> 18], kDigits[(v >> 12) & 63], kDigits[(v >> 6) & 63], kDigits[v & 63]};
  }
  if (const std::size_t rest = in.size() - i; rest > 0) {
    const std::uint32_t v = byte(i) << 16 | (rest == 2 ? byte(i + 1) << 8 : 0);
    out += {kDigits[v >> 18], kDigits[(v >> 12) & 63], rest == 2 ? kDigits[(v >> 6) & 63] : '=', '='};
  }
  return out;
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
  check_32bit_length(bin.size(), embed ? "glTF" : "GLB");

  std::string json = R"({"asset":{"version":"2.0","generator":"remeshd"},"scene":0,)";
  if (soup.points.empty()) {
    json += R"("scenes":[{}]})";  // an empty "nodes" is not valid glTF
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
    if (tris.empty() && lines.empty()) prims = R"({"attributes":{"POSITION":0},"mode":0})";  // POINTS
    json += prims + R"(]}],"accessors":[)" + accessors + R"(],"bufferViews":[)" + views + "],";
    json += R"("buffers":[{"byteLength":)" + std::to_string(bin.size());
    if (embed) json += R"(,"uri":"data:application/octet-stream;base64,)" + base64(bin) + '"';
    json += "}]}";
  }
  return json;
}

}  // namespace

void check_32bit_length(std::size_t bytes, const char* format) {
  if (bytes > std::numeric_limits<std::uint32_t>::max())
    throw std::range_error(std::string(format) + " cannot hold " + std::to_string(bytes) +
                           " bytes of vertices and indices: its lengths are 32-bit, at most 4 GiB");
}

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
  const std::size_t total = 12 + 8 + json.size() + (has_bin ? 8 + bin.size() : 0);
  check_32bit_length(total, "GLB");
  std::string out = "glTF";
  put_le<std::uint32_t>(out, 2);
  put_le<std::uint32_t>(out, static_cast<std::uint32_t>(total));
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
