#include "exr_zip_chunk.hpp"

#include <libdeflate.h>

#include <cstring>
#include <new>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace gvkit::detail {
namespace {

// out[2i] = even[i], out[2i + 1] = odd[i] for 2i + 1 < size; out[size - 1] = even[size / 2] for
// an odd size.
void interleave(const uint8_t* even, const uint8_t* odd, uint8_t* out, size_t size) {
  const size_t pairs = size / 2;
  size_t i = 0;
#if defined(__SSE2__)
  for (; i + 16 <= pairs; i += 16) {
    const __m128i e = _mm_loadu_si128(reinterpret_cast<const __m128i*>(even + i));
    const __m128i o = _mm_loadu_si128(reinterpret_cast<const __m128i*>(odd + i));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 2 * i), _mm_unpacklo_epi8(e, o));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 2 * i + 16), _mm_unpackhi_epi8(e, o));
  }
#endif
  for (; i < pairs; ++i) out[2 * i] = even[i], out[2 * i + 1] = odd[i];
  if (size % 2) out[size - 1] = even[pairs];
}

// The inverse of interleave.
void deinterleave(const uint8_t* in, uint8_t* even, uint8_t* odd, size_t size) {
  const size_t pairs = size / 2;
  size_t i = 0;
#if defined(__SSE2__)
  const __m128i low = _mm_set1_epi16(0x00ff);
  for (; i + 16 <= pairs; i += 16) {
    const __m128i a = _mm_loadu_si128(reinterpret_cast<const __m128i*>(in + 2 * i));
    const __m128i b = _mm_loadu_si128(reinterpret_cast<const __m128i*>(in + 2 * i + 16));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(even + i),
                     _mm_packus_epi16(_mm_and_si128(a, low), _mm_and_si128(b, low)));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(odd + i),
                     _mm_packus_epi16(_mm_srli_epi16(a, 8), _mm_srli_epi16(b, 8)));
  }
#endif
  for (; i < pairs; ++i) even[i] = in[2 * i], odd[i] = in[2 * i + 1];
  if (size % 2) even[pairs] = in[size - 1];
}

// b[i] = b[i] - b[i - 1] + 128 for i >= 1 (mod 256, from the last to the first).
void to_differences(uint8_t* b, size_t size) {
  size_t i = size;
#if defined(__SSE2__)
  const __m128i bias = _mm_set1_epi8(static_cast<char>(128));
  for (; i >= 17; i -= 16) {
    const __m128i x = _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + i - 16));
    const __m128i before = _mm_loadu_si128(reinterpret_cast<const __m128i*>(b + i - 17));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(b + i - 16),
                     _mm_add_epi8(_mm_sub_epi8(x, before), bias));
  }
#endif
  for (; i > 1; --i) b[i - 1] = static_cast<uint8_t>(b[i - 1] - b[i - 2] + 128);
}

// The inverse of to_differences: b[i] = b[i - 1] + b[i] - 128 for i >= 1, a running sum.
void from_differences(uint8_t* b, size_t size) {
  if (size == 0) return;
  size_t i = 1;
#if defined(__SSE2__)
  const __m128i bias = _mm_set1_epi8(static_cast<char>(128));
  __m128i carry = _mm_set1_epi8(static_cast<char>(b[0]));  // the sum so far, in every byte
  for (; i + 16 <= size; i += 16) {
    __m128i x = _mm_sub_epi8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(b + i)), bias);
    x = _mm_add_epi8(x, _mm_slli_si128(x, 1));  // prefix sums within the 16 bytes
    x = _mm_add_epi8(x, _mm_slli_si128(x, 2));
    x = _mm_add_epi8(x, _mm_slli_si128(x, 4));
    x = _mm_add_epi8(x, _mm_slli_si128(x, 8));
    x = _mm_add_epi8(x, carry);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(b + i), x);
    const __m128i top = _mm_unpackhi_epi8(x, x);  // byte 15 into every byte
    carry = _mm_shuffle_epi32(_mm_unpackhi_epi16(top, top), 0xff);
  }
#endif
  uint8_t sum = b[i - 1];
  for (; i < size; ++i) b[i] = sum = static_cast<uint8_t>(sum + b[i] - 128);
}

}  // namespace

ExrZipChunkCoder::ExrZipChunkCoder(int level) : level_(level) {}

ExrZipChunkCoder::~ExrZipChunkCoder() {
  if (compressor_) libdeflate_free_compressor(compressor_);
  if (decompressor_) libdeflate_free_decompressor(decompressor_);
}

const std::vector<uint8_t>& ExrZipChunkCoder::pack(const uint8_t* raw, size_t size) {
  if (!compressor_ && !(compressor_ = libdeflate_alloc_compressor(level_))) throw std::bad_alloc();
  // Even-indexed bytes, then odd-indexed ones; then each as the difference to the one before.
  scratch_.resize(size);
  deinterleave(raw, scratch_.data(), scratch_.data() + (size + 1) / 2, size);
  to_differences(scratch_.data(), size);
  packed_.resize(libdeflate_zlib_compress_bound(compressor_, size));
  const size_t n =
      libdeflate_zlib_compress(compressor_, scratch_.data(), size, packed_.data(), packed_.size());
  if (n == 0 || n >= size) {
    packed_.assign(raw, raw + size);
  } else {
    packed_.resize(n);
  }
  return packed_;
}

bool ExrZipChunkCoder::unpack(const uint8_t* packed, size_t packed_size, uint8_t* raw,
                              size_t size) {
  if (packed_size > size) return false;
  if (packed_size == size) {
    std::memcpy(raw, packed, size);
    return true;
  }
  if (!decompressor_ && !(decompressor_ = libdeflate_alloc_decompressor())) throw std::bad_alloc();
  scratch_.resize(size);
  size_t n = 0;
  if (libdeflate_zlib_decompress(decompressor_, packed, packed_size, scratch_.data(), size, &n) !=
          LIBDEFLATE_SUCCESS ||
      n != size)
    return false;
  from_differences(scratch_.data(), size);
  interleave(scratch_.data(), scratch_.data() + (size + 1) / 2, raw, size);
  return true;
}

}  // namespace gvkit::detail
