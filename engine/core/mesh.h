#pragma once
/// \file mesh.h
/// The mesh types every part of the engine shares: an OpenMesh half-edge mesh with double-precision
/// points, status flags (needed for deletion) and face/vertex normals.

#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

namespace remesh {

struct MeshTraits : public OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
  VertexAttributes(OpenMesh::Attributes::Status | OpenMesh::Attributes::Normal);
  EdgeAttributes(OpenMesh::Attributes::Status);
  HalfedgeAttributes(OpenMesh::Attributes::PrevHalfedge | OpenMesh::Attributes::Status);
  FaceAttributes(OpenMesh::Attributes::Status | OpenMesh::Attributes::Normal);
};

/// A 2-manifold, consistently oriented triangle mesh (the remesher's input and output).
using TriMesh = OpenMesh::TriMesh_ArrayKernelT<MeshTraits>;
/// A polygon mesh (the trivalent dual).
using PolyMesh = OpenMesh::PolyMesh_ArrayKernelT<MeshTraits>;
using Vec3 = OpenMesh::Vec3d;

}  // namespace remesh
