/* pyoa/sampler.hpp: pyoa's samplers behind pbrt-v4's sampler interface, for
 * C++14 (and later) renderers and CUDA kernels. Header-only, on top of the C
 * API of pyoa/sampler.h (docs/renderers.md, "pyoa in your renderer").
 *
 *     pyoa::Sampler s;
 *     std::vector<pyoa_u64> table;                // the sampler's table, if it needs one
 *     pyoa::Status st = pyoa::Sampler::Create(s, "bose", 49, width, height, seed,
 *         [&](std::size_t n) { table.resize((n + 7) / 8); return (void *)table.data(); });
 *     if (!st.ok()) { fprintf(stderr, "%s\n", st.message); ... }
 *     s.StartPixelSample(x, y, sampleIndex);      // or a point with .x and .y
 *     float u = s.Get1D();                        // dimension 0
 *     pyoa::Point2f uv = s.Get2D();               // dimensions 1 and 2
 *
 * Create(s, options, width, height, allocate) takes the C API's
 * pyoa_options instead (dims, offset, jitter, strength, base).
 *
 * The interface is pbrt-v4's (src/pbrt/base/sampler.h): SamplesPerPixel,
 * StartPixelSample(p, sampleIndex, dimension = 0), Get1D, Get2D,
 * GetPixel2D, Clone, and a static Create. Differences from pbrt's, and why:
 * - Create reports an error as a Status (the C API's code and message)
 *   instead of pbrt's ErrorExit, and it does not throw: it works under
 *   -fno-exceptions and in CUDA translation units, and a pbrt wrapper turns
 *   a Status into its own ErrorExit(loc, "%s", st.message) in one line.
 * - Create takes the table's allocator as a callable (`void *(size_t)`),
 *   not a pbrt Allocator: pbrt passes
 *   [&](size_t n) { return alloc.allocate_bytes(n, 8); } (CUDA managed
 *   memory in GPU builds), others their own memory.
 * - Clone() takes no Allocator and returns a copy by value: the class is a
 *   small trivially copyable value (the pyoa_sampler of the C API, the image
 *   width and three counters), which also makes pbrt's wavefront copy
 *   `ConcreteSampler pixelSampler = *sampler.Cast<ConcreteSampler>();` legal
 *   in device code. A copy shares the table (the table is read-only).
 * - Get1D and Get2D return the caller's types: BasicSampler<P, R> returns
 *   R and a P built as P{x, y}. pyoa::Sampler is
 *   BasicSampler<pyoa::Point2f, float>; pbrt derives its wrapper from
 *   BasicSampler<pbrt::Point2f, pbrt::Float>, and so inherits
 *   SamplesPerPixel, StartPixelSample, Get1D, Get2D and GetPixel2D with the
 *   exact return types its TaggedPointer dispatch demands (it
 *   static_asserts that all samplers return the same type, also in a
 *   PBRT_FLOAT_AS_DOUBLE build): no forwarding method to write, where a
 *   fixed pyoa::Point2f would need one per method and a conversion in
 *   each. A double Real holds the float value exactly.
 *
 * Conventions (the same as the C API's, docs/renderers.md):
 * - pixel index = y * width + x (pyoa_pixel_index): row-major over the FULL
 *   image, whose width is given to Create and held here, so a crop window or
 *   a tile reproduces the full frame's values. 0 <= x < width, 0 <= y.
 * - seed: pbrt's `int seed` becomes (pyoa_u32)seed, two's complement (the
 *   same 32 bits pbrt hashes). A frame number is folded in with
 *   FrameSeed(seed, frame): frame 0 keeps the seed, so a still image has
 *   the Python API's values for that seed.
 * - dimensions: StartPixelSample sets the dimension (0 by default); Get1D
 *   reads one and advances by 1, Get2D and GetPixel2D read two (x first)
 *   and advance by 2, as in pbrt. Every value is a stateless function of
 *   (pixel, sample, dimension), so a wavefront integrator may start at any
 *   dimension (pbrt's `6 + 7 * depth`).
 *
 * Every method a kernel calls is PYOA_CPU_GPU (__host__ __device__ under
 * nvcc). Create, TableBytes, FillTable and BindTable run on the host only.
 * The values are pyoa_sampler_value's, bit for bit, on the host and on a
 * GPU (pyoa/config.h: no FMA contraction, __f*_rn intrinsics in CUDA). */
#ifndef PYOA_SAMPLER_HPP
#define PYOA_SAMPLER_HPP

#if !defined(__cplusplus)
#error "pyoa/sampler.hpp is C++ (C++14 or later); C programs include pyoa/sampler.h"
#endif

#include <cstddef>
#include <type_traits>

#include "hashes.h"
#include "sampler.h" /* includes counts.h: pyoa_lookup, pyoa_needs_resolution */

#if defined(__CUDACC__)
#define PYOA_CPU_GPU __host__ __device__
#else
#define PYOA_CPU_GPU
#endif

namespace pyoa {

/* A 2D sample, as Get2D returns it for pyoa::Sampler. */
struct Point2f {
    float x, y;
};

/* The user seed of animation frame `frame` for user seed `seed`
 * (docs/spec.md section 3.5; pyoa_frame_seed of pyoa/hashes.h): the seed
 * itself for frame 0 (a still image keeps the Python API's values for
 * `seed`), else hash_pair(seed, frame, PYOA_FRAME_KEY), an independent
 * randomization per frame. */
PYOA_CPU_GPU inline pyoa_u32 FrameSeed(pyoa_u32 seed, pyoa_u32 frame) { return pyoa_frame_seed(seed, frame); }

/* What Create returns: PYOA_OK, or an error code of pyoa/sampler.h
 * (PYOA_ERROR_NAME, _SPP, ..., _JITTER; or PYOA_ERROR_ALLOCATION, below)
 * with the C API's message: the Python API's ValueError text, which names
 * the nearest valid counts. Host only. */
struct Status {
    int code;
    char message[1024];
    bool ok() const { return code == PYOA_OK; }
};

/* Create's code when the allocator returned no memory, or memory that is
 * not 8-byte aligned; past the C API's codes. */
#define PYOA_ERROR_ALLOCATION 100

template <class Point2 = Point2f, class Real = float>
class BasicSampler {
  public:
    /* Uninitialized, like a pbrt sampler before Create; trivial, so the
     * class stays trivially copyable. */
    BasicSampler() = default;

    /* Wrap a sampler made with the C API (pyoa_sampler_make, its table
     * bound) for an image `width` pixels wide. */
    PYOA_CPU_GPU BasicSampler(const pyoa_sampler &sampler, pyoa_u32 width)
        : sampler_(sampler), width_(width), pixel_(0u), sampleIndex_(0u), dimension_(0u)
    {
    }

    /* Make sampler `name` (a catalogue name or a pbrt/Mitsuba alias: "bose",
     * "cmjnd", "sobol", "independent", ...) with samplesPerPixel samples and
     * the user seed `seed` (pbrt's int: its 32 bits), for a full image of
     * width x height pixels, every other option at its default (the
     * options overload below sets them). If the sampler needs a table,
     * allocate(bytes) is called once and must return 8-byte-aligned memory
     * that outlives the sampler and its copies (host memory, or CUDA managed
     * memory for GPU kernels); Create fills and binds it. On error `out` is
     * left as it was. Host only. */
    template <class Allocate>
    static Status Create(BasicSampler &out, const char *name, int samplesPerPixel, int width, int height, int seed,
                         Allocate allocate)
    {
        if (samplesPerPixel <= 0)
            return error(PYOA_ERROR_SPP, "samplesPerPixel must be positive");
        pyoa_options options = pyoa_options_default(name, (pyoa_u32)samplesPerPixel);
        options.seed = (pyoa_u32)seed;
        return Create(out, options, width, height, allocate);
    }

    /* The same from the C API's options (pyoa_options_default, then dims,
     * offset, jitter, strength, base, seed as needed). width x height is
     * the full image: the class numbers pixels by its width, and the
     * options get it where the sampler needs it (zsobol, zfaure; the C API
     * refuses an image for the others, so theirs stay 0 x 0). */
    template <class Allocate>
    static Status Create(BasicSampler &out, pyoa_options options, int width, int height, Allocate allocate)
    {
        if (width <= 0 || height <= 0)
            return error(PYOA_ERROR_RESOLUTION, "width and height must be positive");
        pyoa_u32 code;
        if (pyoa_lookup(options.name, &code) == PYOA_OK && pyoa_needs_resolution(code)) {
            options.width = (pyoa_u32)width;
            options.height = (pyoa_u32)height;
        }
        Status status;
        status.message[0] = '\0';
        pyoa_sampler s;
        status.code = pyoa_sampler_make(&s, &options, status.message, sizeof status.message);
        if (status.code != PYOA_OK)
            return status;
        std::size_t bytes = pyoa_sampler_table_bytes(&s);
        if (bytes != 0u) {
            void *table = allocate(bytes);
            if (table == nullptr || (reinterpret_cast<std::size_t>(table) & 7u) != 0u)
                return error(PYOA_ERROR_ALLOCATION, "the allocator returned no 8-byte-aligned memory for the "
                                                    "sampler's table");
            pyoa_sampler_fill_table(&s, table);
            pyoa_sampler_bind_table(&s, table);
        }
        out = BasicSampler(s, (pyoa_u32)width);
        return status;
    }

    /* pbrt's interface. */
    PYOA_CPU_GPU int SamplesPerPixel() const { return (int)sampler_.spp; }

    /* Start sample `sampleIndex` of the pixel at raster position (x, y) of
     * the full image, at `dimension`. */
    PYOA_CPU_GPU void StartPixelSample(int x, int y, int sampleIndex, int dimension = 0)
    {
        pixel_ = pyoa_pixel_index((pyoa_u32)x, (pyoa_u32)y, width_);
        sampleIndex_ = (pyoa_u32)sampleIndex;
        dimension_ = (pyoa_u32)dimension;
    }

    /* The same for any point type with integer members x and y (pbrt's
     * Point2i); other argument types are left to the overload above. */
    template <class P, class = decltype(static_cast<const P *>(nullptr)->x + static_cast<const P *>(nullptr)->y)>
    PYOA_CPU_GPU void StartPixelSample(const P &p, int sampleIndex, int dimension = 0)
    {
        StartPixelSample((int)p.x, (int)p.y, sampleIndex, dimension);
    }

    /* The value at the current dimension; the dimension advances by 1. Real
     * is float, or pbrt's Float (double in a PBRT_FLOAT_AS_DOUBLE build:
     * every float converts to it exactly). */
    PYOA_CPU_GPU Real Get1D() { return (Real)pyoa_sampler_value(&sampler_, pixel_, sampleIndex_, dimension_++); }

    /* The values at the current dimension (x) and the next (y); the
     * dimension advances by 2. */
    PYOA_CPU_GPU Point2 Get2D()
    {
        Real x = (Real)pyoa_sampler_value(&sampler_, pixel_, sampleIndex_, dimension_);
        Real y = (Real)pyoa_sampler_value(&sampler_, pixel_, sampleIndex_, dimension_ + 1u);
        dimension_ += 2u;
        return Point2{x, y};
    }

    /* The film position within the pixel: Get2D, as pbrt's stateless
     * samplers (PaddedSobol, ZSobol, PMJ02BN, Independent) do. */
    PYOA_CPU_GPU Point2 GetPixel2D() { return Get2D(); }

    /* A copy (pbrt's Clone(alloc) returns a new object; this class is a
     * value). The copy shares the table. */
    PYOA_CPU_GPU BasicSampler Clone() const { return *this; }

    /* Beyond pbrt's interface. */
    PYOA_CPU_GPU const pyoa_sampler &CSampler() const { return sampler_; }
    PYOA_CPU_GPU pyoa_u32 Width() const { return width_; }
    PYOA_CPU_GPU pyoa_u32 PixelIndex() const { return pixel_; }
    PYOA_CPU_GPU pyoa_u32 SampleIndex() const { return sampleIndex_; }
    PYOA_CPU_GPU pyoa_u32 Dimension() const { return dimension_; }

    /* The table, for a caller that places it itself (CUDA device memory:
     * fill a host buffer, copy it to the device, bind the device copy).
     * Host only. */
    std::size_t TableBytes() const { return pyoa_sampler_table_bytes(&sampler_); }
    void FillTable(void *buffer) const { pyoa_sampler_fill_table(&sampler_, buffer); }
    void BindTable(const void *buffer) { pyoa_sampler_bind_table(&sampler_, buffer); }

  private:
    static Status error(int code, const char *text)
    {
        static const char prefix[] = "pyoa::Sampler::Create: ";
        Status status;
        std::size_t n = 0;
        status.code = code;
        for (const char *p = prefix; *p != '\0'; ++p)
            status.message[n++] = *p;
        for (; *text != '\0' && n + 1 < sizeof status.message; ++text)
            status.message[n++] = *text;
        status.message[n] = '\0';
        return status;
    }

    pyoa_sampler sampler_;
    pyoa_u32 width_;
    pyoa_u32 pixel_;
    pyoa_u32 sampleIndex_;
    pyoa_u32 dimension_;
};

typedef BasicSampler<Point2f, float> Sampler;

static_assert(std::is_trivially_copyable<Sampler>::value,
              "pyoa::Sampler is copied by value into kernels (pbrt's wavefront copy)");

}  // namespace pyoa

#endif /* PYOA_SAMPLER_HPP */
