// The peers' rate accounting: SEI NAL units found and sized in Annex B streams of H.264 and HEVC.

#include <gtest/gtest.h>

#include <string>

#include "annexb_sei.hpp"

namespace gvkit::bench {
namespace {

int64_t sei_of(AnnexBCodec codec, const std::string& s) {
  return annexb_sei_bytes(codec, reinterpret_cast<const uint8_t*>(s.data()), s.size());
}

// A NAL unit: 4-byte start code, header byte(s), then payload bytes.
std::string nal(const std::string& header, int payload) {
  return std::string("\0\0\0\1", 4) + header + std::string(payload, '\x5a');
}

TEST(AnnexBSei, H264CountsOnlyTheSeiUnitsWithTheirStartCodes) {
  const std::string sps = nal("\x67", 10);   // type 7
  const std::string sei = nal("\x06", 600);  // type 6: the encoder's banner
  const std::string idr = nal("\x65", 900);  // type 5
  // The SEI unit's 3-byte start code, its header byte and payload, and the leading zero of the
  // next unit's 4-byte start code (which counts with the unit before it).
  EXPECT_EQ(sei_of(AnnexBCodec::kH264, sps + sei + idr), 3 + 1 + 600 + 1);
  EXPECT_EQ(sei_of(AnnexBCodec::kH264, sps + idr), 0);
  EXPECT_EQ(sei_of(AnnexBCodec::kH264, sps + idr + sei), 3 + 1 + 600);  // the last unit
}

TEST(AnnexBSei, HevcCountsPrefixAndSuffixSei) {
  const std::string vps = nal(std::string("\x40\x01", 2), 20);       // type 32
  const std::string prefix = nal(std::string("\x4e\x01", 2), 2200);  // type 39
  const std::string slice = nal(std::string("\x26\x01", 2), 3000);   // type 19 (IDR)
  const std::string suffix = nal(std::string("\x50\x01", 2), 30);    // type 40
  EXPECT_EQ(sei_of(AnnexBCodec::kHevc, vps + prefix + slice + suffix),
            (3 + 2 + 2200 + 1) + (3 + 2 + 30));
  EXPECT_EQ(sei_of(AnnexBCodec::kHevc, vps + slice), 0);
  // An H.264 SEI header byte (0x06) is HEVC type 3, not SEI.
  EXPECT_EQ(sei_of(AnnexBCodec::kHevc, nal("\x06", 50)), 0);
}

TEST(AnnexBSei, DataWithoutStartCodesHasNoUnits) {
  EXPECT_EQ(sei_of(AnnexBCodec::kH264, std::string(100, '\x06')), 0);
  EXPECT_EQ(sei_of(AnnexBCodec::kH264, ""), 0);
  EXPECT_EQ(sei_of(AnnexBCodec::kH264, std::string("\0\0\1", 3)), 0);  // a start code at the end
}

}  // namespace
}  // namespace gvkit::bench
