// The smallest player: opens a .gvid (or a folder of frame_NNNNNN.exr) and shows it in a 3D
// window (needs a display and OpenGL 3.3). --check opens the video and decodes its first frame
// without a window, for machines without a display.
//   mini_player FILE.gvid [--check]
#include <cstdio>
#include <cstring>
#include <memory>

#include <gvkit/player/frame_sequence.hpp>
#include <gvkit/player/player_window.hpp>

int main(int argc, char** argv) {
  const bool check = argc == 3 && std::strcmp(argv[2], "--check") == 0;
  if (argc != 2 && !check) {
    std::fprintf(stderr, "usage: %s FILE.gvid [--check]\n", argv[0]);
    return 2;
  }
  auto sequence = gvkit::player::FrameSequence::create(argv[1]);
  if (!sequence.is_ok()) {
    std::fprintf(stderr, "error: %s\n", sequence.status().message().c_str());
    return 1;
  }
  std::printf("%s: %lld frames at %.1f fps\n", (*sequence)->name().c_str(),
              static_cast<long long>((*sequence)->frame_count()), (*sequence)->fps());
  auto first = (*sequence)->frame(0);
  if (!first.is_ok()) {
    std::fprintf(stderr, "error: %s\n", first.status().message().c_str());
    return 1;
  }
  std::printf("first frame %dx%d\n", first->size().width, first->size().height);
  if (check) return 0;
  gvkit::player::PlayerWindowOptions options;
  options.sequence = std::move(sequence).value();
  options.title = "mini_player";
  if (gvkit::Status s = gvkit::player::run_player_window(options); !s.is_ok()) {
    std::fprintf(stderr, "error: %s\n", s.message().c_str());
    return 1;
  }
  return 0;
}
