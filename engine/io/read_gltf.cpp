/// \file read_gltf.cpp
/// glTF 2.0 (.gltf with data: URIs, and .glb) through tinygltf. Every triangle primitive
/// (TRIANGLES, TRIANGLE_STRIP, TRIANGLE_FAN) of every mesh reachable from the default scene (else
/// from every scene, else every root node) is merged with its node transforms applied. The
/// reader never opens a file: external URIs are refused, images are never decoded.

#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/parse_util.h"
#include "io/soup.h"

namespace remesh::io {

namespace {

using Mat4 = std::array<double, 16>;  // column-major, as glTF

/// Records the first external file tinygltf asked for; every file access is refused.
struct FsGuard {
  std::string first_external;
};

bool refuse_exists(const std::string& path, void* user) {
  auto* g = static_cast<FsGuard*>(user);
  if (g->first_external.empty()) g->first_external = path.empty() ? "(empty)" : path;
  return false;
}
std::string keep_path(const std::string& path, void*) { return path; }
bool refuse_read(std::vector<unsigned char>*, std::string* err, const std::string& path, void* user) {
  refuse_exists(path, user);
  if (err) *err = "external files are not read";
  return false;
}
bool refuse_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err = "writing files is disabled";
  return false;
}
bool skip_image(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*) {
  return true;
}

Mat4 identity() { return {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; }

Mat4 multiply(const Mat4& a, const Mat4& b) {
  Mat4 r{};
  for (int c = 0; c < 4; ++c)
    for (int row = 0; row < 4; ++row) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a[k * 4 + row] * b[c * 4 + k];
      r[c * 4 + row] = s;
    }
  return r;
}

Mat4 local_transform(const tinygltf::Node& n) {
  if (n.matrix.size() == 16) {
    Mat4 m;
    for (int i = 0; i < 16; ++i) m[i] = n.matrix[i];
    return m;
  }
  Mat4 t = identity(), r = identity(), s = identity();
  if (n.translation.size() == 3) for (int i = 0; i < 3; ++i) t[12 + i] = n.translation[i];
  if (n.scale.size() == 3) for (int i = 0; i < 3; ++i) s[i * 5] = n.scale[i];
  if (n.rotation.size() == 4) {
    const double x = n.rotation[0], y = n.rotation[1], z = n.rotation[2], w = n.rotation[3];
    r = {1 - 2 * (y * y + z * z), 2 * (x * y + z * w),     2 * (x * z - y * w),     0,
         2 * (x * y - z * w),     1 - 2 * (x * x + z * z), 2 * (y * z + x * w),     0,
         2 * (x * z + y * w),     2 * (y * z - x * w),     1 - 2 * (x * x + y * y), 0,
         0, 0, 0, 1};
  }
  return multiply(t, multiply(r, s));
}

double det3(const Mat4& m) {
  return m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) +
         m[8] * (m[1] * m[6] - m[5] * m[2]);
}

/// A bounds-checked view of one accessor's elements.
struct AccessorView {
  const unsigned char* base = nullptr;
  std::size_t stride = 0, count = 0;
};

AccessorView view_of(const tinygltf::Model& model, int index, const std::string& what, std::size_t elem_size) {
  if (index < 0 || static_cast<std::size_t>(index) >= model.accessors.size())
    fail("glTF: " + what + " refers to missing accessor " + std::to_string(index));
  const tinygltf::Accessor& a = model.accessors[static_cast<std::size_t>(index)];
  if (a.sparse.isSparse) fail("glTF: " + what + " uses a sparse accessor (not supported)");
  if (a.bufferView < 0 || static_cast<std::size_t>(a.bufferView) >= model.bufferViews.size())
    fail("glTF: " + what + " accessor " + std::to_string(index) + " has no valid bufferView");
  const tinygltf::BufferView& v = model.bufferViews[static_cast<std::size_t>(a.bufferView)];
  if (v.buffer < 0 || static_cast<std::size_t>(v.buffer) >= model.buffers.size())
    fail("glTF: bufferView " + std::to_string(a.bufferView) + " refers to a missing buffer");
  const auto& data = model.buffers[static_cast<std::size_t>(v.buffer)].data;
  // Every sum and product checked before it is formed: offsets near 2^64 would wrap round and
  // pass a test of the sum, and the reads would land before the buffer.
  const std::uint64_t stride = v.byteStride ? v.byteStride : elem_size;
  const std::uint64_t size = data.size(), view_offset = v.byteOffset, view_length = v.byteLength,
                      offset = a.byteOffset;
  if (view_offset > size || view_length > size - view_offset)
    fail("glTF: bufferView " + std::to_string(a.bufferView) + " reaches past the end of its buffer (offset " +
         std::to_string(view_offset) + ", length " + std::to_string(view_length) + ", buffer " +
         std::to_string(size) + " bytes)");
  bool fits = stride >= elem_size && offset <= view_length;
  if (fits && a.count > 0) {
    const std::uint64_t room = view_length - offset;  // bytes of the view from the accessor's first element
    fits = room >= elem_size && a.count - 1 <= (room - elem_size) / stride;
  }
  if (!fits)
    fail("glTF: " + what + " accessor " + std::to_string(index) + " reaches past the end of its bufferView (offset " +
         std::to_string(offset) + ", " + std::to_string(a.count) + " elements of stride " + std::to_string(stride) +
         ", view " + std::to_string(view_length) + " bytes)");
  return {data.data() + view_offset + offset, static_cast<std::size_t>(stride), a.count};
}

class Collector {
 public:
  Collector(const tinygltf::Model& model, const ReadOptions& options, std::size_t input_bytes)
      : model_(model), options_(options), max_points_(std::max<std::size_t>(64 * input_bytes, 1 << 20)),
        max_triangles_(std::max<std::size_t>(16 * input_bytes, 1 << 22)) {}

  void node(int index, const Mat4& parent, int depth) {
    if (index < 0 || static_cast<std::size_t>(index) >= model_.nodes.size())
      fail("glTF: reference to missing node " + std::to_string(index));
    if (depth > kMaxDepth)
      fail("glTF: the node hierarchy is more than " + std::to_string(kMaxDepth) + " levels deep (or has a cycle)");
    // A flat scene visits each node once; a hierarchy that shares subtrees may visit one node
    // exponentially often (each level referencing the next twice): bounded here, and its
    // triangles by max_triangles_. (A flat scene of over 100 000 nodes was refused as a cycle.)
    const std::size_t max_visits = std::max<std::size_t>(kMinVisits, 4 * model_.nodes.size());
    if (++visits_ > max_visits)
      fail("glTF: the scene visits its nodes more than " + std::to_string(max_visits) + " times (subtrees shared too often)");
    const tinygltf::Node& n = model_.nodes[static_cast<std::size_t>(index)];
    const Mat4 m = multiply(parent, local_transform(n));
    if (n.mesh >= 0) mesh(n.mesh, m, index);
    for (int child : n.children) node(child, m, depth + 1);
  }

  /// `node`: the node that places the mesh, for messages (-1: none, a scene without nodes).
  void mesh(int index, const Mat4& m, int node) {
    if (static_cast<std::size_t>(index) >= model_.meshes.size())
      fail("glTF: reference to missing mesh " + std::to_string(index));
    const auto& prims = model_.meshes[static_cast<std::size_t>(index)].primitives;
    for (std::size_t p = 0; p < prims.size(); ++p)
      primitive(prims[p], "mesh " + std::to_string(index) + " primitive " + std::to_string(p), m, node);
  }

  /// The soup; a scene whose primitives are all points or lines is refused saying so (it read as
  /// "no vertices and no faces").
  RawSoup take() {
    if (soup_.face_count() == 0 && skipped_mode_ >= 0)
      fail("glTF: its primitives are " + std::string(skipped_mode_ == TINYGLTF_MODE_POINTS ? "points" : "lines") +
           " (mode " + std::to_string(skipped_mode_) + "), no triangles: there is no surface to remesh");
    return std::move(soup_);
  }

 private:
  void primitive(const tinygltf::Primitive& prim, const std::string& what, const Mat4& m, int node) {
    const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) {
      if (skipped_mode_ < 0) skipped_mode_ = mode;
      return;  // points and lines carry no surface
    }
    if (prim.extensions.count("KHR_draco_mesh_compression"))
      fail("glTF: " + what + " is Draco-compressed (not supported)");
    auto pos = prim.attributes.find("POSITION");
    if (pos == prim.attributes.end()) fail("glTF: " + what + " has no POSITION attribute");
    AccessorView pv = view_of(model_, pos->second, what + " POSITION", 12);
    const auto& pa = model_.accessors[static_cast<std::size_t>(pos->second)];
    if (pa.type != TINYGLTF_TYPE_VEC3 || pa.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
      fail("glTF: " + what + " POSITION must be VEC3 of FLOAT" +
           (pa.type == TINYGLTF_TYPE_VEC3 ? " (integer positions, KHR_mesh_quantization, are not read)" : ""));
    const std::size_t first = soup_.points.size();
    // Instancing can multiply geometry: cap what one upload may expand to.
    if (first + pv.count > max_points_)
      fail("glTF: the scene expands to more than " + std::to_string(max_points_) + " vertices");
    // Said here, not as a vertex of the soup: a transform that overflows (scales of 1e200 on two
    // levels) or holds a NaN makes every point it places non-finite. (Only where it places some:
    // a node whose mesh has only lines or points, or no positions, reads as before.)
    if (pv.count > 0 && !std::all_of(m.begin(), m.end(), [](double x) { return std::isfinite(x); }))
      fail("glTF: node " + std::to_string(node) +
           "'s transform (its matrix, translation, rotation or scale, times its parents') is not finite");
    for (std::size_t i = 0; i < pv.count; ++i) {
      float c[3];
      std::memcpy(c, pv.base + i * pv.stride, 12);
      // Named as stored: the node transform would spread one NaN to all three coordinates.
      if (!std::isfinite(c[0]) || !std::isfinite(c[1]) || !std::isfinite(c[2])) {
        char coords[96];
        std::snprintf(coords, sizeof coords, "(%g, %g, %g)", c[0], c[1], c[2]);
        fail("glTF: " + what + " POSITION element " + std::to_string(i) + " has a non-finite coordinate " + coords);
      }
      Vec3 p;
      for (int r = 0; r < 3; ++r) p[r] = m[r] * c[0] + m[4 + r] * c[1] + m[8 + r] * c[2] + m[12 + r];
      if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
        char coords[96];
        std::snprintf(coords, sizeof coords, "(%g, %g, %g)", c[0], c[1], c[2]);
        fail("glTF: " + what + " POSITION element " + std::to_string(i) + " " + coords +
             " is past the range of double once its node's transform is applied");
      }
      soup_.points.push_back(p);
    }
    std::vector<std::int64_t> idx;
    if (prim.indices >= 0) {
      if (static_cast<std::size_t>(prim.indices) >= model_.accessors.size())
        fail("glTF: " + what + " refers to missing index accessor " + std::to_string(prim.indices));
      const auto& ia = model_.accessors[static_cast<std::size_t>(prim.indices)];
      std::size_t size = 0;
      switch (ia.componentType) {
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: size = 1; break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: size = 2; break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: size = 4; break;
        default: fail("glTF: " + what + " indices must be unsigned byte, short or int");
      }
      if (ia.type != TINYGLTF_TYPE_SCALAR) fail("glTF: " + what + " indices must be SCALAR");
      AccessorView iv = view_of(model_, prim.indices, what + " indices", size);
      idx.reserve(iv.count);
      for (std::size_t i = 0; i < iv.count; ++i) {
        const unsigned char* b = iv.base + i * iv.stride;
        std::uint32_t v = 0;
        if (size == 1) v = b[0];
        else if (size == 2) { std::uint16_t s; std::memcpy(&s, b, 2); v = s; }
        else std::memcpy(&v, b, 4);
        if (v >= pv.count)
          fail("glTF: " + what + " index " + std::to_string(i) + " is " + std::to_string(v) +
               " but POSITION has " + std::to_string(pv.count) + " elements");
        idx.push_back(static_cast<std::int64_t>(first + v));
      }
    } else {
      for (std::size_t i = 0; i < pv.count; ++i) idx.push_back(static_cast<std::int64_t>(first + i));
    }
    const bool flip = det3(m) < 0;
    // Instancing multiplies the triangles too (a node listing the same child twice, 16 levels deep:
    // a 300 KB file expanded to 3.3e9 triangles, 4 GB and counting): the same kind of cap.
    const std::size_t per_face = mode == TINYGLTF_MODE_TRIANGLES ? 3 : 1;
    if (soup_.face_count() + idx.size() / per_face > max_triangles_)
      fail("glTF: the scene expands to more than " + std::to_string(max_triangles_) +
           " triangles (its nodes instance the same meshes over and over)");
    auto add = [&](std::int64_t a, std::int64_t b, std::int64_t c) {
      check_face_limit(soup_.face_count() + 1, options_, "glTF");
      if (flip) std::swap(b, c);
      soup_.indices.insert(soup_.indices.end(), {a, b, c});
      soup_.offsets.push_back(static_cast<std::uint32_t>(soup_.indices.size()));
    };
    const std::size_t n = idx.size();
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      for (std::size_t i = 0; i + 2 < n; i += 3) add(idx[i], idx[i + 1], idx[i + 2]);
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      for (std::size_t i = 0; i + 2 < n; ++i)
        if (i % 2 == 0) add(idx[i], idx[i + 1], idx[i + 2]);
        else add(idx[i + 1], idx[i], idx[i + 2]);
    } else {
      for (std::size_t i = 1; i + 1 < n; ++i) add(idx[0], idx[i], idx[i + 1]);
    }
  }

  const tinygltf::Model& model_;
  const ReadOptions& options_;
  RawSoup soup_;
  static constexpr int kMaxDepth = 64;
  static constexpr std::size_t kMinVisits = 100000;
  std::size_t visits_ = 0;
  std::size_t max_points_;
  std::size_t max_triangles_;  ///< what the scene may expand to (instancing)
  int skipped_mode_ = -1;      ///< the mode of the first primitive of points or lines passed over
};

/// How deep arrays and objects nest in a JSON text (strings skipped), stopping once past `limit`.
/// tinygltf's parser recurses once a level: a 40 KB file of 20 000 nested brackets in "extras"
/// overflowed the stack (the service process died on the upload).
std::size_t json_depth(std::string_view text, std::size_t limit) {
  std::size_t depth = 0, deepest = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
      if (deepest > limit) break;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

/// Deepest nesting of the glTF JSON accepted (a glTF document itself needs about 6 levels).
constexpr std::size_t kMaxJsonDepth = 256;

/// The JSON text of a .gltf file, or of a GLB's first chunk (whatever its header says, within the file).
std::string_view json_text(std::string_view bytes, bool binary) {
  if (!binary) return bytes;
  if (bytes.size() < 20) return {};
  ByteReader r(bytes, 12);
  const std::uint32_t length = r.read<std::uint32_t>(false);
  return bytes.substr(20, std::min<std::size_t>(length, bytes.size() - 20));
}

/// The first line of tinygltf's error, without the JSON library's tag ("[json.exception.parse_error.101] ").
std::string first_line(const std::string& s) {
  std::string t = s.substr(0, s.find('\n'));
  if (const std::size_t tag = t.find("[json.exception."); tag != std::string::npos)
    if (const std::size_t end = t.find("] ", tag); end != std::string::npos) t.erase(tag, end + 2 - tag);
  return t.empty() ? "unknown error" : t;
}

}  // namespace

RawSoup read_gltf(std::string_view bytes, bool binary, const ReadOptions& options) {
  if (bytes.size() >= 0xFFFFFFF0u) fail("glTF: files of 4 GB or more are not supported");
  if (binary) {
    if (bytes.size() < 20 || bytes.substr(0, 4) != "glTF") fail("GLB: missing the 'glTF' header");
    ByteReader r(bytes, 4);
    const std::uint32_t version = r.read<std::uint32_t>(false);
    if (version != 2) fail("GLB: version " + std::to_string(version) + " (only glTF 2.0 is supported)");
    // A file cut short: tinygltf said only "Invalid glTF binary."
    const std::uint32_t declared = r.read<std::uint32_t>(false);
    if (declared > bytes.size())
      fail("GLB: the file is " + std::to_string(bytes.size()) + " bytes, but its header says " +
           std::to_string(declared) + " (cut short?)");
    ByteReader chunk(bytes, 12);
    const std::uint32_t json_length = chunk.read<std::uint32_t>(false);
    if (20 + static_cast<std::uint64_t>(json_length) > bytes.size())
      fail("GLB: its JSON chunk of " + std::to_string(json_length) + " bytes reaches past the end of the file (" +
           std::to_string(bytes.size()) + " bytes; cut short?)");
  }
  if (json_depth(json_text(bytes, binary), kMaxJsonDepth) > kMaxJsonDepth)
    fail(std::string(binary ? "GLB" : "glTF") + ": its JSON nests arrays and objects more than " +
         std::to_string(kMaxJsonDepth) + " levels deep");
  FsGuard guard;
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(&skip_image, nullptr);
  loader.SetFsCallbacks({&refuse_exists, &keep_path, &refuse_read, &refuse_write, &guard});
  tinygltf::Model model;
  std::string err, warn;
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  const auto size = static_cast<unsigned int>(bytes.size());
  bool ok = false;
  try {
    ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, data, size, "")
                : loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(), size, "");
  } catch (const std::exception& e) {
    // tinygltf 2.7 reads some malformed files through std::vector::at (a GLB whose buffer has
    // byteLength 0: its BIN chunk is copied to data.at(0)), which throws std::out_of_range.
    fail(std::string(binary ? "GLB" : "glTF") + ": malformed structure the glTF loader could not read (" +
         e.what() + ")");
  }
  // A file tinygltf asked for (every request is refused): when the load failed for it, a buffer
  // lies outside the upload. An image's (a texture file, or a data: URI of a type it does not
  // decode, such as webp) only warns: the surface is read without it (a textured file was refused
  // for its texture). A data: URI tinygltf does not know is asked for as a file.
  if (!ok && guard.first_external.starts_with("data:"))
    fail("glTF: a buffer's data: URI that this reader does not decode (" + quote(guard.first_external.substr(0, 40)) +
         "); it reads base64 data of type application/octet-stream or application/gltf-buffer, or a .glb");
  if (!ok && !guard.first_external.empty())
    fail("glTF refers to an external file " + quote(guard.first_external) +
         "; only embedded data (data: URIs or .glb) is accepted");
  if (!ok) fail(std::string(binary ? "GLB" : "glTF") + ": " + first_line(err));

  // An extension the file requires that changes where its surface lies: read without it, the
  // positions were compressed bytes (EXT_meshopt_compression), or one copy of an instanced mesh
  // stood for all (EXT_mesh_gpu_instancing). Any other is read past: about looks (materials,
  // textures), or about attributes this reader does not use (KHR_mesh_quantization, which
  // three.js's exporter requires for 8- and 16-bit normals; quantized positions are refused
  // below, naming it). Draco is named per primitive below.
  for (const std::string& ext : model.extensionsRequired) {
    if (ext == "EXT_meshopt_compression")
      fail(std::string(binary ? "GLB" : "glTF") + ": its buffers are compressed (EXT_meshopt_compression), which "
                                                  "this reader does not decode");
    if (ext == "EXT_mesh_gpu_instancing")
      fail(std::string(binary ? "GLB" : "glTF") + ": it holds instanced meshes (EXT_mesh_gpu_instancing), which "
                                                  "this reader does not expand");
  }
  Collector collect(model, options, bytes.size());
  const int scene = model.defaultScene;
  if (scene >= 0 && static_cast<std::size_t>(scene) < model.scenes.size()) {
    for (int n : model.scenes[static_cast<std::size_t>(scene)].nodes) collect.node(n, identity(), 0);
  } else if (!model.scenes.empty()) {
    for (const auto& s : model.scenes)
      for (int n : s.nodes) collect.node(n, identity(), 0);
  } else {
    std::vector<bool> is_child(model.nodes.size(), false);
    for (const auto& n : model.nodes)
      for (int c : n.children)
        if (c >= 0 && static_cast<std::size_t>(c) < is_child.size()) is_child[static_cast<std::size_t>(c)] = true;
    for (std::size_t n = 0; n < model.nodes.size(); ++n)
      if (!is_child[n]) collect.node(static_cast<int>(n), identity(), 0);
    if (model.nodes.empty())
      for (std::size_t m = 0; m < model.meshes.size(); ++m) collect.mesh(static_cast<int>(m), identity(), -1);
  }
  return collect.take();
}

}  // namespace remesh::io

