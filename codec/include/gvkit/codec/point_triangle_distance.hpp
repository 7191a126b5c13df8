#pragma once
// Squared distance from a point to triangles in 3D, for the surface metrics' vertex-to-surface
// distances (surface_metrics.hpp). The nearest point of a triangle is found by Voronoi region
// (Ericson, Real-Time Collision Detection 5.1.5); a degenerate triangle (the barycentric
// denominator not finite) gives the distance to its nearest corner. Units are those of the
// input (millimetres in gvkit), squared.
//
// The search prunes triangles with bounding spheres (spheres_within_reach).
//
// nearest_triangle_distance2 and spheres_within_reach take AVX-512 where the processor has it
// (eight triangles or spheres per step), else AVX2 (four), and return the same values bit for bit
// as their *_reference versions (the same operations in the same order, no fused multiply-add:
// the file is compiled with -ffp-contract=off); tests/codec/surface_metrics_test.cpp compares them
// on random and degenerate input, once more with GVKIT_SIMD=avx2 (core/cpu_features.hpp).

#include <cstdint>

#include <opencv2/core.hpp>

namespace gvkit::codec {

// The squared distance from p to triangle abc.
double point_triangle_distance2(const cv::Vec3d& p, const cv::Vec3d& a, const cv::Vec3d& b,
                                const cv::Vec3d& c);

// Vertex coordinates as three arrays indexed by vertex.
struct VertexArrays {
  const double* x = nullptr;
  const double* y = nullptr;
  const double* z = nullptr;
};

// Triangles as three arrays of vertex indices (corners a, b, c), indexed by triangle.
struct TriangleIndices {
  const int32_t* a = nullptr;
  const int32_t* b = nullptr;
  const int32_t* c = nullptr;
};

// min(bound, the squared distance from p to each of triangles 0..n-1 of t), the corners' indices
// into v; n >= 0. Only the first n entries of t's arrays are read. Coordinates finite (contract).
double nearest_triangle_distance2(const cv::Vec3d& p, const VertexArrays& v,
                                  const TriangleIndices& t, int n, double bound);
double nearest_triangle_distance2_reference(const cv::Vec3d& p, const VertexArrays& v,
                                            const TriangleIndices& t, int n, double bound);

// Spheres as arrays of centre coordinates and radii, indexed by sphere; a radius < 0 marks an
// empty sphere.
struct SphereArrays {
  const double* x = nullptr;
  const double* y = nullptr;
  const double* z = nullptr;
  const double* radius = nullptr;
};

// Bit k (k < n <= 32) set when a point of sphere k may lie closer than `reach` to p:
// |p - centre|^2 < (radius + reach)^2 with radius >= 0. Only the first n entries are read.
uint32_t spheres_within_reach(const cv::Vec3d& p, const SphereArrays& s, int n, double reach);
uint32_t spheres_within_reach_reference(const cv::Vec3d& p, const SphereArrays& s, int n,
                                        double reach);

}  // namespace gvkit::codec
