#include "nn/bfloat16.h"

#include <algorithm>
#include <bit>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define FIGNET_HAVE_BF16_TARGET 1
#endif

namespace fignet::detail {

Bf16 to_bf16(float x) {
  const auto bits = std::bit_cast<std::uint32_t>(x);
  // A NaN could round up into infinity: keep its upper bits and make it quiet.
  if ((bits & 0x7fffffffu) > 0x7f800000u) return static_cast<Bf16>((bits >> 16) | 0x40u);
  // Adding 0x7fff rounds the upper half up when the lower half is above the tie; the upper half's
  // lowest bit breaks the tie toward even.
  return static_cast<Bf16>((bits + 0x7fffu + ((bits >> 16) & 1u)) >> 16);
}

float from_bf16(Bf16 x) {
  return std::bit_cast<float>(static_cast<std::uint32_t>(x) << 16);
}

namespace {

void round_to_bf16_portable(const float* in, Bf16* out, Eigen::Index n) {
  for (Eigen::Index i = 0; i < n; ++i) out[i] = to_bf16(in[i]);
}

#ifdef FIGNET_HAVE_BF16_TARGET
// vcvtneps2bf16: 16 floats per instruction, round to nearest even like to_bf16.
__attribute__((target("avx512f,avx512bf16"))) void round_to_bf16_avx512(const float* in, Bf16* out,
                                                                        Eigen::Index n) {
  Eigen::Index i = 0;
  for (; i + 16 <= n; i += 16) {
    const __m256bh rounded = _mm512_cvtneps_pbh(_mm512_loadu_ps(in + i));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + i),
                        reinterpret_cast<const __m256i&>(rounded));
  }
  round_to_bf16_portable(in + i, out + i, n - i);
}
#endif

}  // namespace

void round_to_bf16(const float* in, Bf16* out, Eigen::Index n) {
#ifdef FIGNET_HAVE_BF16_TARGET
  static const bool has_instruction = __builtin_cpu_supports("avx512bf16");
  if (has_instruction) {
    round_to_bf16_avx512(in, out, n);
    return;
  }
#endif
  round_to_bf16_portable(in, out, n);
}

void copy_to_bf16(const ConstMatrixRef& x, Eigen::Index rows, Eigen::Index cols, Bf16* out) {
  eigen_assert(rows >= x.rows() && cols >= x.cols());
  for (Eigen::Index r = 0; r < x.rows(); ++r) {
    Bf16* row = out + r * cols;
    round_to_bf16(x.row(r).data(), row, x.cols());
    std::fill(row + x.cols(), row + cols, Bf16{0});
  }
  std::fill(out + x.rows() * cols, out + rows * cols, Bf16{0});
}

}  // namespace fignet::detail
