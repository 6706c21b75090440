#pragma once
/// \file mesh_io.h
/// Reading meshes from bytes or files (OBJ, OFF, PLY, STL, glTF/GLB), validating and repairing them
/// into a 2-manifold, consistently oriented TriMesh; writing triangle and polygon meshes.
///
/// Reading never touches the disk except for the one file named by read_mesh_file(); a .gltf whose
/// buffers point to external files is refused (MeshError). All functions are thread-safe.
///
/// Validation and repair, in this order (element indices in messages are 0-based, in file order;
/// text formats add " (line N)"):
///   refused (MeshError): empty input; unknown format; malformed syntax ("OBJ line 12: bad vertex
///     coordinate 'x'"); numbers past the largest double ("... '1e400' (too large: ...)"; one
///     nearer 0 than any double reads as the nearest, 0 or a denormal); counts that do not fit the file ("OFF header claims ... but only N bytes
///     follow"); records an OFF or PLY file ends before ("OFF: file ends after 3 of 4 faces"; the
///     last line of a text file needs no line break); non-finite coordinates ("vertex 7 (line 9)
///     has a non-finite coordinate (nan, 0, 1)"); faces with < 3 vertices ("face 4 (line 9) has 2
///     vertices; a face needs at least 3"); indices out of range, as the file counts them ("face 1 (line 6) refers to
///     vertex 9, but there are 4 vertices (OBJ counts from 1)"); edges with more than two faces
///     ("non-manifold mesh: N edges are shared by more than 2 faces; the first joins vertices A and
///     B (shared by k faces, e.g. face F (line L))"); non-orientable components ("non-orientable
///     surface (e.g. a Moebius strip): ..."); no face left ("all N faces are degenerate or
///     duplicates; no surface is left").
///   repaired (Repair::kind, in this order): "polygons_triangulated" (ear clipping);
///     "vertices_welded" (only with ReadOptions::weld, never creating a non-manifold edge);
///     "degenerate_faces_repaired" (zero area: twice the area <= 1e-12 * longest edge^2; mended
///     on the half-edge mesh keeping its topology: a needle's near-zero edge collapsed, the edge
///     a cap lies on flipped, a cap on the boundary removed); "degenerate_faces_removed" (faces
///     with a repeated vertex, and zero-area faces that would make an edge non-manifold or the
///     surface non-orientable, or that no collapse or flip repairs: these can leave a hole);
///     "duplicate_faces_removed" (same vertex set in any order, the first kept);
///     "faces_reoriented" (per connected component, the minority is flipped);
///     "nonmanifold_vertices_split" (one copy per extra fan of a pinched vertex);
///     "unreferenced_vertices_removed".
///   STL corners are welded by exact position while reading (STL has no indices): not a repair.
///   LimitError when ReadOptions::max_faces is exceeded (checked on header counts before
///   allocating, and again after triangulation). Header counts the file's bytes cannot hold are a
///   MeshError first, limit or not: a small file claiming a billion faces is malformed, not too large.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/errors.h"
#include "core/mesh.h"

namespace remesh {

enum class Format { Obj, Off, Ply, Stl, Gltf, Glb, Xyz, Lammps };

/// "obj", "off", "ply", "stl", "gltf", "glb", "xyz", "lammps". parse_format() also takes "lmp" and
/// "data" (the usual extensions of LAMMPS data files) for Lammps.
std::string_view format_name(Format f);
/// Parses a name or extension ("obj", ".OBJ", "mesh.ply" -> Ply); nullopt if unknown.
std::optional<Format> parse_format(std::string_view name_or_path);
/// Sniffs the format from the first bytes; nullopt if nothing matches.
std::optional<Format> detect_format(std::string_view bytes);

/// One repair made while reading, e.g. {"polygons_triangulated", 12, "12 polygons fan-triangulated"}.
struct Repair {
  std::string kind;    ///< stable machine name
  std::size_t count;   ///< how many elements it touched
  std::string detail;  ///< one line for people, names where (indices, lines)
};

struct ReadOptions {
  std::optional<Format> format;  ///< from the caller (extension, Content-Type); else sniffed
  bool weld = false;             ///< weld vertices at exactly the same position, except where an
                                 ///< edge would get more than 2 faces (pinches it makes are split)
  std::size_t max_faces = 0;     ///< refuse (LimitError) meshes with more faces; 0 = no limit
};

struct LoadedMesh {
  TriMesh mesh;                 ///< valid 2-manifold, consistently oriented, normals updated
  Format format;                ///< the format it was read as
  std::vector<Repair> repairs;  ///< every repair made, in order
};

/// Reads a mesh from memory. Throws MeshError naming the problem (and LimitError over max_faces).
LoadedMesh read_mesh(std::string_view bytes, const ReadOptions& options = {});
/// Reads a file; the format comes from the extension, else from the content.
LoadedMesh read_mesh_file(const std::string& path, ReadOptions options = {});

/// A neutral polygon list for writing: face f has indices[offsets[f] .. offsets[f+1]).
struct PolygonSoup {
  std::vector<Vec3> points;
  std::vector<std::uint32_t> indices;
  std::vector<std::uint32_t> offsets{0};
};
PolygonSoup to_soup(const TriMesh& mesh);
PolygonSoup to_soup(const PolyMesh& mesh);

/// Serialises to bytes. Polygons: OBJ/OFF/PLY keep them; STL fan-triangulates; GLB writes a
/// triangle-fan primitive plus a LINES primitive of the true polygon edges (points without faces:
/// a POINTS primitive); XYZ writes one atom
/// ("C x y z") per point; Lammps writes a LAMMPS data file (atom_style bond): one carbon atom per
/// point and one bond per edge of the faces (no Bonds section without edges), in a box 5 % wider
/// than their bounding box. Gltf is the GLB's document as text, its buffer a base64 data: URI. XYZ
/// and Lammps are written, not read. Throws std::invalid_argument for unsupported;
/// std::range_error for STL, GLB and glTF, which store float32, when a point has a coordinate of
/// about 3.4e38 or more in magnitude, and for GLB and glTF past 4 GiB of data (nothing is written).
std::string write_mesh(const PolygonSoup& soup, Format format);
std::string write_mesh(const TriMesh& mesh, Format format);
std::string write_mesh(const PolyMesh& mesh, Format format);
/// Writes to a file, format from the extension. Throws MeshError if unknown, std::range_error as
/// write_mesh() before creating the file, std::runtime_error on I/O.
void write_mesh_file(const PolygonSoup& soup, const std::string& path);

/// The MIME type served for a format (model/obj, model/gltf-binary, ...).
std::string_view mime_type(Format f);

}  // namespace remesh
