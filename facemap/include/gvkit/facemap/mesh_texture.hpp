#pragma once
// A texture image mapped onto a mesh by per-face corner texture coordinates (an OBJ with a map_Kd
// material, a PLY with `comment TextureFile`), kept beside the mesh: renders of the mesh show it
// (mesh_landmarks), vertex colours can be taken from it, and landmarks given as pixels of the
// texture image find their place on the surface through it.
//
// Texture coordinates: u right, v up, [0, 1] over the image; pixel (x, y) (x right, y down, pixel
// centres at integers) = (u W - 0.5, (1 - v) H - 0.5) for a W x H image.

#include <array>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/mesh.hpp"
#include "gvkit/core/status.hpp"

namespace gvkit::facemap {

struct MeshTexture {
  std::vector<cv::Mat> images;  // CV_8UC3 (BGR)
  // Per face of the mesh (by face index): its image (index into images, -1: none) and the
  // (u, v) of its corners in the order the mesh lists the face's vertices (fv_range).
  std::vector<int> face_image;
  std::vector<std::array<cv::Vec2f, 3>> face_uv;
  bool empty() const { return face_image.empty(); }
};

cv::Vec2d texture_pixel(const cv::Mat& image, const cv::Vec2f& uv);
cv::Vec2f texture_uv(const cv::Mat& image, const cv::Point2f& pixel);

// The grey value in [0, 1] at `uv` (bilinear, clamped at the border).
float sample_texture_grey(const cv::Mat& image, const cv::Vec2f& uv);

// Vertex colours (RGB, alpha 1) from the texture: per vertex the mean colour at its textured
// corners; vertices without one keep their colour or get mid grey. Requests vertex colours.
void colour_vertices_from_texture(const MeshTexture& texture, Mesh* mesh);

struct TexturePointOptions {
  // A pixel on no textured face (between charts of the texture atlas) takes the nearest textured
  // face up to this far in the image; farther fails.
  double max_gap_px = 4.0;
  // A pixel on several faces (overlapping or mirrored charts) is ambiguous when their surface
  // points lie farther apart than this (mm); nearer ones are averaged.
  double max_spread_mm = 2.0;
  Status check() const;
};

// The surface points (mesh frame) of pixels of texture image `image`. Fails naming `name` and the
// point (its index in `pixels`) that lies on no textured face, or on faces far apart.
Result<std::vector<cv::Vec3d>> surface_points_of_texture_pixels(
    const Mesh& mesh, const MeshTexture& texture, int image, const std::vector<cv::Point2f>& pixels,
    const std::string& name, const TexturePointOptions& options = {});

}  // namespace gvkit::facemap
