// bfloat16 copies of float matrices: the operands of the products gemm() runs in bf16
// (GemmPrecision::kBf16). A bfloat16 is a float's upper 16 bits (sign, 8-bit exponent, 7 stored
// mantissa bits): same range, ~3 significant decimal digits.
#pragma once

#include <cstdint>
#include <vector>

#include "fignet/nn/buffer.h"

namespace fignet::detail {

using Bf16 = std::uint16_t;
using AlignedBf16 = std::vector<Bf16, Eigen::aligned_allocator<Bf16>>;

// x rounded to the nearest bfloat16, ties to even (what processors' conversion instructions do);
// NaN stays NaN.
Bf16 to_bf16(float x);
float from_bf16(Bf16 x);

// n floats rounded to bfloat16, with the processor's conversion instruction where it has one
// (AVX512-BF16, chosen at run time), the same bits as to_bf16 either way.
void round_to_bf16(const float* in, Bf16* out, Eigen::Index n);

// A bf16 copy of x (any row stride) as a dense row-major rows x cols matrix at out, zeros beyond
// x's rows and columns: padding that adds nothing to a product it enters. rows >= x.rows(),
// cols >= x.cols().
void copy_to_bf16(const ConstMatrixRef& x, Eigen::Index rows, Eigen::Index cols, Bf16* out);

}  // namespace fignet::detail
