#include "annexb_sei.hpp"

#include <vector>

namespace gvkit::bench {

int64_t annexb_sei_bytes(AnnexBCodec codec, const uint8_t* data, size_t size) {
  std::vector<size_t> starts;  // first byte of each NAL unit (after its start code)
  for (size_t i = 0; i + 2 < size; ++i)
    if (data[i] == 0 && data[i + 1] == 0 && data[i + 2] == 1) {
      starts.push_back(i + 3);
      i += 2;
    }
  int64_t sei = 0;
  for (size_t k = 0; k < starts.size(); ++k) {
    const size_t begin = starts[k];
    if (begin >= size) break;
    const size_t end = k + 1 < starts.size() ? starts[k + 1] - 3 : size;
    const int type = codec == AnnexBCodec::kH264 ? data[begin] & 0x1F : (data[begin] >> 1) & 0x3F;
    const bool is_sei = codec == AnnexBCodec::kH264 ? type == 6 : (type == 39 || type == 40);
    if (is_sei) sei += static_cast<int64_t>(end - begin + 3);
  }
  return sei;
}

}  // namespace gvkit::bench
