/* pyoa/config.h: what the portable headers need from the language they are
 * compiled as: OpenCL C, C99 (or later), C++14 (or later), or CUDA (nvcc).
 *
 * Every value function of pyoa's headers is PYOA_FN: a static inline
 * function (in CUDA also __host__ __device__), with no heap, no mutable
 * global and no state, safe from any thread or GPU lane.
 *
 * Bit-exactness (docs/spec.md section 7) is guarded here, not left to the
 * caller's flags:
 * - every float operation the spec rounds on its own is written with
 *   PYOA_ADD, PYOA_SUB, PYOA_MUL and PYOA_DIV. In CUDA device code they are
 *   the round-to-nearest intrinsics (__fadd_rn, ...), which nvcc never
 *   contracts into an FMA and whose division is correctly rounded whatever
 *   --fmad, --prec-div or --use_fast_math say (--use_fast_math's
 *   --ftz=true still flushes subnormal results to zero, which pyoa's
 *   values meet only through a jitter amount below about 1e-28;
 *   docs/renderers.md, CUDA); elsewhere they are the plain operators, with
 *   contraction switched off below;
 * - contraction off: OpenCL's FP_CONTRACT pragma; clang's STDC FP_CONTRACT;
 *   GCC, whose ISO modes (-std=c99, -std=c++14) do not contract but whose
 *   GNU modes do (-ffp-contract=fast), gets the optimize pragma for the
 *   functions that follow (GCC warns of an unknown STDC pragma, and
 *   -Werror would refuse it); MSVC contracts only under /fp:fast or
 *   /fp:contract, which pyoa's headers refuse (below);
 * - OpenCL's '/' is correctly rounded only when the program is built with
 *   -cl-fp32-correctly-rounded-divide-sqrt (pyoa/_opencl/program.py);
 * - x87 arithmetic (FLT_EVAL_METHOD 1 or 2: 32-bit x86 without SSE) rounds
 *   float intermediates to a wider format, and is refused (16, GCC's value
 *   with AVX512-FP16, concerns _Float16 only: float keeps its own format).
 */
#ifndef PYOA_CONFIG_H
#define PYOA_CONFIG_H

#if defined(__OPENCL_VERSION__)
/* ---------------------------------------------------------------- OpenCL C */
#pragma OPENCL FP_CONTRACT OFF
typedef uint pyoa_u32;
typedef ushort pyoa_u16;
typedef ulong pyoa_u64;
#define PYOA_FN static inline
#define PYOA_GLOBAL __global
#define PYOA_MIN(a, b) min(a, b)
#define PYOA_MAX(a, b) max(a, b)
#define PYOA_AS_F32(u) as_float(u)
#define PYOA_AS_U32(f) as_uint(f)
#define PYOA_U32_TO_F32(u) convert_float_rte(u)
#define PYOA_FMA(a, b, c) fma(a, b, c)

#else
/* ------------------------------------------------------ C, C++ and CUDA */
#if defined(__cplusplus)
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>
#else
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <string.h>
#endif
typedef uint32_t pyoa_u32;
typedef uint16_t pyoa_u16;
typedef uint64_t pyoa_u64;
/* The address space of the tables the value functions read: OpenCL's
 * __global, nothing elsewhere (a CUDA caller passes device pointers). */
#define PYOA_GLOBAL
/* min and max of two unsigned integers (OpenCL's built-ins there); the
 * arguments are evaluated twice. */
#define PYOA_MIN(a, b) ((a) < (b) ? (a) : (b))
#define PYOA_MAX(a, b) ((a) > (b) ? (a) : (b))

#if defined(FLT_EVAL_METHOD) && (FLT_EVAL_METHOD == 1 || FLT_EVAL_METHOD == 2) && !defined(__CUDA_ARCH__)
#error "pyoa: float expressions here are evaluated in a wider format (FLT_EVAL_METHOD 1 or 2, x87); build with SSE2 (-msse2 -mfpmath=sse)"
#endif
#if defined(_MSC_VER) && !defined(__clang__) && defined(_M_FP_FAST)
#error "pyoa: /fp:fast reorders and contracts float operations; build pyoa's headers with /fp:precise"
#endif

#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#elif defined(__GNUC__) && !defined(__CUDACC__)
#pragma GCC optimize("fp-contract=off")
#endif

#if defined(__CUDACC__)
#define PYOA_FN static __host__ __device__ __forceinline__
#else
#define PYOA_FN static inline
#endif
/* Functions that run on the host only: making a sampler, filling its
 * tables (they may loop long and write to caller-owned memory). */
#define PYOA_HOST_FN static inline

PYOA_FN float pyoa_as_f32(pyoa_u32 u)
{
#if defined(__CUDA_ARCH__)
    return __uint_as_float(u);
#else
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
#endif
}

PYOA_FN pyoa_u32 pyoa_as_u32(float f)
{
#if defined(__CUDA_ARCH__)
    return __float_as_uint(f);
#else
    pyoa_u32 u;
    memcpy(&u, &f, sizeof u);
    return u;
#endif
}

/* uint32 to the nearest float32, ties to even: C's conversion in the
 * default rounding mode, which pyoa's callers must not change. */
PYOA_FN float pyoa_u32_to_f32(pyoa_u32 u)
{
#if defined(__CUDA_ARCH__)
    return __uint2float_rn(u);
#else
    return (float)u;
#endif
}

#define PYOA_AS_F32(u) pyoa_as_f32(u)
#define PYOA_AS_U32(f) pyoa_as_u32(f)
#define PYOA_U32_TO_F32(u) pyoa_u32_to_f32(u)
#if defined(__CUDA_ARCH__)
#define PYOA_FMA(a, b, c) __fmaf_rn(a, b, c)
#else
#define PYOA_FMA(a, b, c) fmaf(a, b, c)
#endif
#endif

/* The four correctly rounded operations (see the top of this file). */
#if defined(__CUDA_ARCH__)
#define PYOA_ADD(a, b) __fadd_rn(a, b)
#define PYOA_SUB(a, b) __fsub_rn(a, b)
#define PYOA_MUL(a, b) __fmul_rn(a, b)
#define PYOA_DIV(a, b) __fdiv_rn(a, b)
#else
#define PYOA_ADD(a, b) ((a) + (b))
#define PYOA_SUB(a, b) ((a) - (b))
#define PYOA_MUL(a, b) ((a) * (b))
#define PYOA_DIV(a, b) ((a) / (b))
#endif

#endif /* PYOA_CONFIG_H */
