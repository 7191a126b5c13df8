#pragma once
// Internal: a z-buffer triangle rasterizer on per-pixel undistorted rays. A pixel is covered by a
// triangle when its ray (x, y, 1) passes through it; depth and barycentrics are exact on the
// ray (perspective-correct), so lens distortion only changes which pixel holds which ray.

#include <vector>

#include <opencv2/core.hpp>

#include "gvkit/core/calibration.hpp"

namespace gvkit::capture::detail {

struct DepthBuffer {
  cv::Mat depth;        // CV_32F, z (mm), +inf where empty
  cv::Mat triangle;     // CV_32S, -1 where empty
  cv::Mat barycentric;  // CV_32FC3
};

// rays: CV_32FC2 normalized coordinates of each pixel. K, dist: the device's lens (to find the
// pixel box of a triangle). points_mm: vertices in the device's frame.
DepthBuffer rasterize(const std::vector<cv::Vec3d>& points_mm,
                      const std::vector<cv::Vec3i>& triangles, const cv::Mat& rays,
                      const cv::Matx33d& K, const std::vector<double>& dist);

// Normalized undistorted coordinates of every pixel of a device.
cv::Mat pixel_rays(const cv::Matx33d& K, const std::vector<double>& dist, cv::Size size);

// Distorted pixel position of a point in the device frame (z > 0).
cv::Point2d project_point(const cv::Vec3d& p, const cv::Matx33d& K,
                          const std::vector<double>& dist);

}  // namespace gvkit::capture::detail
