// codec_bd_rate ANCHOR TEST: BD-rate (piecewise cubic, bd_rate.hpp) of two rate-distortion curves
// given as "rate:psnr,rate:psnr,..." (e.g. bits/vertex/frame : geometry PSNR in dB), for
// comparing the tables of two runs (e.g. before and after an encoder change).
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "bd_rate.hpp"

namespace {

std::vector<gvkit::bench::RdPoint> parse(const std::string& text) {
  std::vector<gvkit::bench::RdPoint> points;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    const size_t colon = item.find(':');
    if (colon == std::string::npos) continue;
    points.push_back(
        {std::atof(item.substr(0, colon).c_str()), std::atof(item.substr(colon + 1).c_str())});
  }
  return points;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s ANCHOR TEST (each \"rate:psnr,rate:psnr,...\")\n", argv[0]);
    return 2;
  }
  const auto bd = gvkit::bench::bd_rate_percent(parse(argv[1]), parse(argv[2]));
  if (!bd) {
    std::fprintf(stderr, "the curves share no PSNR interval (or have < 2 points)\n");
    return 1;
  }
  std::printf("BD-rate %+.2f %%\n", *bd);
  return 0;
}
