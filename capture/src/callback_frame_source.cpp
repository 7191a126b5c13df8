#include "gvkit/capture/callback_frame_source.hpp"

#include <chrono>
#include <utility>

#include "pacer.hpp"

namespace gvkit {
namespace {

class CallbackFrameSource final : public FrameSource {
 public:
  CallbackFrameSource(FrameGenerator generator, const FrameSourceOptions& options, std::string name)
      : generator_(std::move(generator)),
        options_(options),
        name_(std::move(name)),
        pacer_(options.paced ? options.fps : 0) {
    GVKIT_CHECK(generator_ != nullptr, "callback source without a generator");
  }

  Result<std::optional<CameraFrame>> next() override {
    if (!failure_.is_ok()) return failure_;
    if (options_.drop_late) {
      // A camera does not wait for its consumer: slots that passed are lost, and counted.
      const std::optional<int64_t> now_index = pacer_.index_now();
      if (now_index && *now_index > index_) {
        counters_.dropped += *now_index - index_;
        index_ = *now_index;
      }
    }
    if (finished_ || (options_.frame_count > 0 && index_ >= options_.frame_count))
      return std::optional<CameraFrame>();
    pacer_.wait_for(index_);
    const auto generating = std::chrono::steady_clock::now();
    Result<cv::Mat> image = generator_(index_);
    if (options_.drop_late) {
      // The generator's own time is the simulation's, not the consumer's: the camera's clock
      // pauses meanwhile, so only a slow consumer makes frames late.
      const auto spent = std::chrono::steady_clock::now() - generating;
      pacer_.pause_for(spent);
    }
    if (!image.is_ok())
      return failure_ = image.status().with_context(name_ + ": frame " + std::to_string(index_));
    if (image->empty()) {
      finished_ = true;
      return std::optional<CameraFrame>();
    }
    if (image->channels() != 1 || (image->depth() != CV_8U && image->depth() != CV_16U))
      return failure_ = unsupported(name_ + ": frame " + std::to_string(index_) +
                                    ": the generator gave a " + std::to_string(image->channels()) +
                                    "-channel image of depth " + std::to_string(image->depth()) +
                                    "; expected one channel, CV_8U or CV_16U");
    CameraFrame frame;
    frame.image = std::move(image).value();
    frame.sequence = index_;
    if (options_.pattern_cycle > 0) {
      const int position = static_cast<int>(index_ % options_.pattern_cycle);
      frame.pattern = position < options_.cue_frames ? -1 : position - options_.cue_frames;
    }
    if (!options_.paced && options_.fps > 0)
      frame.timestamp =
          Timestamp(static_cast<int64_t>(static_cast<double>(index_) * 1e9 / options_.fps));
    else
      frame.timestamp = monotonic_now();
    ++index_;
    ++counters_.frames;
    return std::optional<CameraFrame>(std::move(frame));
  }

  FrameSourceCounters counters() const override { return counters_; }

  std::string describe() const override {
    std::string text = name_ + " (generated frames";
    if (options_.fps > 0) text += ", " + std::to_string(options_.fps) + " fps";
    text += options_.paced ? ", paced" : ", unpaced";
    if (options_.drop_late) text += ", late frames dropped";
    text += ")";
    return text;
  }

 private:
  FrameGenerator generator_;
  FrameSourceOptions options_;
  std::string name_;
  detail::Pacer pacer_;
  int64_t index_ = 0;
  bool finished_ = false;
  Status failure_;
  FrameSourceCounters counters_;
};

}  // namespace

std::unique_ptr<FrameSource> make_callback_source(FrameGenerator generator,
                                                  const FrameSourceOptions& options,
                                                  std::string name) {
  return std::make_unique<CallbackFrameSource>(std::move(generator), options, std::move(name));
}

}  // namespace gvkit
