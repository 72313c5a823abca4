// One kernel body for SIMD batches and for scalars. A kernel is written once as a template on
// a lane type V (xsimd::batch<float, A> or plain float); its scalar instantiation handles the
// tail. Because V's operators map one-to-one onto IEEE single-precision operations (no FMA:
// the build uses -ffp-contract=off and the kernels never call fma; sqrt and division are
// exact), every element sees the same operations in the same order whatever the vector
// width, so SSE, AVX2, AVX-512 and scalar builds give the same bits.
#pragma once
#include <cmath>
#include <cstddef>

#ifndef PAPERTEAR_NO_SIMD
// GCC 12 reports "'__Y' is used uninitialized" inside its own avx512fintrin.h wherever an
// _mm512_undefined_* intrinsic is inlined (those are uninitialised by design); the warning
// cannot be silenced at the include, only in the translation units that inline them. Only
// the kernel sources include this header.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <xsimd/xsimd.hpp>
#endif

namespace papertear::lanes {

template <class V>
struct Traits;

template <>
struct Traits<float> {
  static constexpr std::size_t width = 1;
  static float load(const float* p) { return *p; }
  static void store(float* p, float v) { *p = v; }
  static float broadcast(float v) { return v; }
  static float sqrt(float v) { return std::sqrt(v); }
  // True when every lane's value is inside (-limit, limit) (false for NaN).
  static bool all_within(float v, float limit) { return std::fabs(v) < limit; }
};

#ifndef PAPERTEAR_NO_SIMD
template <class A>
struct Traits<xsimd::batch<float, A>> {
  using V = xsimd::batch<float, A>;
  static constexpr std::size_t width = V::size;
  static V load(const float* p) { return V::load_aligned(p); }
  static void store(float* p, const V& v) { v.store_aligned(p); }
  static V broadcast(float v) { return V(v); }
  static V sqrt(const V& v) { return xsimd::sqrt(v); }
  static bool all_within(const V& v, float limit) { return xsimd::all(xsimd::abs(v) < V(limit)); }
};
// The widest float batch the build targets (-march): 4 lanes (SSE), 8 (AVX2) or 16 (AVX-512).
using Wide = xsimd::batch<float>;
#else
using Wide = float;
#endif

inline constexpr std::size_t kMaxWidth = 16;

}  // namespace papertear::lanes
