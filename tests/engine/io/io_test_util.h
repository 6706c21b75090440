#pragma once
/// \file io_test_util.h
/// Helpers for the io tests: a small mesh serialised in every input format (including the
/// variants our writers do not produce: ASCII/big-endian PLY, binary OFF, ASCII STL, a .gltf of
/// 16-bit indices), and an independent validity check of a loaded mesh.

#include <string>
#include <vector>

#include "io/mesh_io.h"

namespace remesh::test {

struct SampleFile {
  std::string name;  ///< e.g. "ply_be"
  Format format;
  std::string bytes;
};

/// `soup` written in every input format and variant.
std::vector<SampleFile> sample_files(const PolygonSoup& soup);

/// Individual variants (the rest come from write_mesh()).
std::string write_ply_ascii(const PolygonSoup& soup);
std::string write_ply_big_endian(const PolygonSoup& soup);
std::string write_off_binary(const PolygonSoup& soup);
std::string write_stl_ascii(const PolygonSoup& soup);
/// Base64 (RFC 4648, padded), written here independently of the engine's (tinygltf's).
std::string base64(const std::string& in);
/// A .gltf whose one buffer is a base64 data: URI (or `uri` verbatim if not empty).
std::string write_gltf_data_uri(const PolygonSoup& soup, const std::string& uri = "");

/// A soup from explicit points and faces.
PolygonSoup make_soup(const std::vector<Vec3>& points, const std::vector<std::vector<std::uint32_t>>& faces);

/// Zero area as the reader defines it: twice the area <= 1e-12 x the longest edge squared
/// (computed here on the plain differences of the points).
bool zero_area(const Vec3& a, const Vec3& b, const Vec3& c);

/// Empty if the loaded mesh keeps the reader's promises: at least one face, all faces triangles
/// with three distinct vertices and not of zero_area(), finite points, every vertex manifold and
/// used, each edge with one or two faces, normals set. Otherwise the first problem.
std::string check_loaded(const TriMesh& mesh);

/// Checks (Catch2) that `got` has the same points as `want`, in order, and the same faces, vertex
/// by vertex.
void check_same_mesh(const LoadedMesh& got, const LoadedMesh& want);

}  // namespace remesh::test
