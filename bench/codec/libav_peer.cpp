#include "libav_peer.hpp"

#include <time.h>

#include <chrono>
#include <cstdio>
#include <cstring>

#include "annexb_sei.hpp"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavutil/error.h>
#include <libavutil/log.h>
#include <libavutil/opt.h>
#include <libavutil/pixdesc.h>
}

namespace gvkit::bench {
namespace {

std::string av_message(int err) {
  char buf[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(err, buf, sizeof(buf));
  return buf;
}

// CPU time of the whole process (all threads): the machine is shared, so wall time is noisy;
// CPU seconds are what "frames per second on one core" means.
struct Clock {
  using time_point = double;
  static double now() {
    timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
  }
};

// SEI bytes of a packet (0 for codecs other than H.264 and HEVC): not counted as rate.
int64_t sei_bytes(AVCodecID codec, const uint8_t* data, int size) {
  if (codec != AV_CODEC_ID_H264 && codec != AV_CODEC_ID_HEVC) return 0;
  return annexb_sei_bytes(codec == AV_CODEC_ID_H264 ? AnnexBCodec::kH264 : AnnexBCodec::kHevc, data,
                          static_cast<size_t>(size));
}

}  // namespace

Result<PeerRun> run_peer(const std::vector<std::vector<codec::SamplePlane>>& frames, int width,
                         int height, const PeerConfig& config) {
  av_log_set_level(AV_LOG_ERROR);
  const AVCodec* enc = avcodec_find_encoder_by_name(config.encoder.c_str());
  if (!enc) return unsupported(config.encoder + ": encoder not available in libavcodec");
  const AVPixelFormat fmt = av_get_pix_fmt(config.pix_fmt.c_str());
  AVCodecContext* ec = avcodec_alloc_context3(enc);
  ec->width = width;
  ec->height = height;
  ec->pix_fmt = fmt;
  ec->time_base = {1, 30};
  ec->framerate = {30, 1};
  ec->gop_size = config.gop;
  ec->max_b_frames = config.bframes;
  ec->thread_count = 1;
  for (const auto& [k, v] : config.options)
    av_opt_set(ec, k.c_str(), v.c_str(), AV_OPT_SEARCH_CHILDREN);
  int err = avcodec_open2(ec, enc, nullptr);
  if (err < 0) {
    avcodec_free_context(&ec);
    return unsupported(config.encoder + " " + config.pix_fmt + ": " + av_message(err));
  }
  PeerRun run;
  std::vector<AVPacket*> packets;
  AVFrame* frame = av_frame_alloc();
  frame->format = fmt;
  frame->width = width;
  frame->height = height;
  av_frame_get_buffer(frame, 0);
  AVPacket* pkt = av_packet_alloc();
  const auto drain = [&]() {
    while (avcodec_receive_packet(ec, pkt) == 0) {
      const int64_t sei = sei_bytes(enc->id, pkt->data, pkt->size);
      run.frame_bytes.push_back(pkt->size - sei);
      run.sei_bytes += sei;
      packets.push_back(av_packet_clone(pkt));
      av_packet_unref(pkt);
    }
  };
  auto t0 = Clock::now();
  for (size_t f = 0; f < frames.size(); ++f) {
    av_frame_make_writable(frame);
    for (int p = 0; p < 3; ++p)
      for (int y = 0; y < height; ++y) {
        auto* row = reinterpret_cast<uint16_t*>(frame->data[p] +
                                                static_cast<size_t>(y) * frame->linesize[p]);
        for (int x = 0; x < width; ++x) row[x] = frames[f][p].at(x, y);
      }
    frame->pts = static_cast<int64_t>(f);
    if ((err = avcodec_send_frame(ec, frame)) < 0) {
      fprintf(stderr, "send_frame failed\n");
      break;
    }
    drain();
  }
  avcodec_send_frame(ec, nullptr);
  drain();
  run.encode_seconds = (Clock::now() - t0);
  if (run.sei_bytes > 0)
    std::fprintf(stderr, "%s: %lld bytes of SEI messages not counted in the rate\n",
                 config.encoder.c_str(), static_cast<long long>(run.sei_bytes));
  av_frame_free(&frame);

  const AVCodec* dec = avcodec_find_decoder(enc->id);
  AVCodecContext* dc = avcodec_alloc_context3(dec);
  dc->thread_count = 1;
  dc->width = ec->width;
  dc->height = ec->height;
  dc->pix_fmt = ec->pix_fmt;
  dc->bits_per_raw_sample = ec->bits_per_raw_sample;
  if (ec->extradata_size > 0) {
    dc->extradata =
        static_cast<uint8_t*>(av_mallocz(ec->extradata_size + AV_INPUT_BUFFER_PADDING_SIZE));
    memcpy(dc->extradata, ec->extradata, ec->extradata_size);
    dc->extradata_size = ec->extradata_size;
  }
  avcodec_free_context(&ec);
  if (err >= 0 && (err = avcodec_open2(dc, dec, nullptr)) < 0)
    fprintf(stderr, "decoder open failed\n");
  if (err < 0) {
    avcodec_free_context(&dc);
    return unsupported(config.encoder + ": " + av_message(err));
  }
  AVFrame* out = av_frame_alloc();
  const auto receive = [&]() {
    while (avcodec_receive_frame(dc, out) == 0) {
      std::vector<codec::SamplePlane> planes(3);
      for (int p = 0; p < 3; ++p) {
        planes[p].width = width;
        planes[p].height = height;
        planes[p].samples.resize(static_cast<size_t>(width) * height);
        for (int y = 0; y < height; ++y) {
          const auto* row = reinterpret_cast<const uint16_t*>(
              out->data[p] + static_cast<size_t>(y) * out->linesize[p]);
          for (int x = 0; x < width; ++x) planes[p].at(x, y) = row[x];
        }
      }
      run.decoded.push_back(std::move(planes));
    }
  };
  t0 = Clock::now();
  for (AVPacket* p : packets) {
    avcodec_send_packet(dc, p);
    receive();
    av_packet_free(&p);
  }
  avcodec_send_packet(dc, nullptr);
  receive();
  run.decode_seconds = (Clock::now() - t0);
  av_frame_free(&out);
  av_packet_free(&pkt);
  avcodec_free_context(&dc);
  if (run.decoded.size() != frames.size())
    return failed_precondition(config.encoder + ": decoded " + std::to_string(run.decoded.size()) +
                               " of " + std::to_string(frames.size()) + " frames");
  return run;
}

}  // namespace gvkit::bench
