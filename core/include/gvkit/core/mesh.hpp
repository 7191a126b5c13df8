#pragma once
// Mesh: the triangle mesh type shared by I/O, facemap and the player. OpenMesh array kernel
// with double-precision points (mm), and optional per-vertex normals, texture coordinates and
// colours. facemap keeps its own properties (feature sets) on top of this type.

#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

namespace gvkit {

struct MeshTraits : public OpenMesh::DefaultTraitsDouble {
  using Color = OpenMesh::Vec4f;  // RGBA in [0, 1]; grey texture is r = g = b, alpha 1
  VertexAttributes(OpenMesh::Attributes::Status);
  FaceAttributes(OpenMesh::Attributes::Status);
  EdgeAttributes(OpenMesh::Attributes::Status);
  HalfedgeAttributes(OpenMesh::Attributes::PrevHalfedge);
};

using Mesh = OpenMesh::TriMesh_ArrayKernelT<MeshTraits>;

}  // namespace gvkit
