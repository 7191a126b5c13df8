#pragma once
// The V4L2 frame source ("v4l2:/dev/videoN"): mmap streaming of GREY, Y16 (little-endian 16 bit),
// YUYV (luma kept) or MJPEG (decoded to grey) frames.
//  - Size, fps (VIDIOC_S_PARM) and manual exposure (V4L2_CID_EXPOSURE_AUTO = manual,
//    V4L2_CID_EXPOSURE_ABSOLUTE in 100 us units) are applied where the driver allows; what it
//    refuses or changes is listed by refused_settings(). A refused pixel format is an error.
//  - Row stride is bytesperline as the driver reports it after VIDIOC_S_FMT.
//  - Gaps in the buffer sequence numbers count as dropped frames; buffers flagged
//    V4L2_BUF_FLAG_ERROR (or too short to hold a frame, or undecodable MJPEG) are discarded and
//    counted as errored.
//  - Timestamps: the buffer's CLOCK_MONOTONIC timestamp when the driver marks it monotonic, else
//    the monotonic time of dequeue; never decreasing (a backwards step is clamped and counted).
//  - EINTR and EAGAIN are retried; a vanished device (ENODEV) ends the stream with a Status.

#include <memory>
#include <string>

#include "gvkit/capture/frame_source.hpp"
#include "gvkit/capture/v4l2_io.hpp"

namespace gvkit {

// Opens, configures and starts streaming. Fails with a Status naming the device: no such device,
// permission denied, busy, not a capture device, no streaming, a pixel format the device lacks
// (listing the ones it has and the ones gvkit reads), buffer allocation failures.
Result<std::unique_ptr<FrameSource>> open_v4l2_source(const std::string& device,
                                                      const FrameSourceOptions& options);
Result<std::unique_ptr<FrameSource>> open_v4l2_source(const std::string& device,
                                                      const FrameSourceOptions& options,
                                                      std::shared_ptr<V4l2Io> io);

// "GREY" for V4L2_PIX_FMT_GREY; non-printable bytes become '?'.
std::string fourcc_name(uint32_t fourcc);

}  // namespace gvkit
