// examples/cpp/integrate7d.cpp: pyoa's C++ class (pyoa/sampler.hpp), with
// pbrt-v4's sampler interface, in a C++14 program.
//
// The same experiment as examples/c/integrate7d.c, and the same numbers: each
// pixel of a 32 x 32 image estimates the integral over [0, 1)^7 of Genz's
// "Gaussian" test function with a_j = 1 and u_j = 1/2,
//
//     f(x) = exp(-sum_{j=1..7} (x_j - 1/2)^2),   exact: (sqrt(pi) erf(1/2))^7 = 0.56881...,
//
// and the program prints the RMS error over the pixels for the chosen
// sampler and for pyoa's `random` sampler at the same spp. Here the seven
// values are drawn as a renderer draws them: StartPixelSample at the pixel's
// raster position, then GetPixel2D (film position: dimensions 0 and 1),
// Get1D (time: 2), Get2D (lens: 3 and 4) and Get2D (a light sample: 5 and
// 6). Those are dimensions 0..6 in order, so the output equals the C
// example's, byte for byte (tests/test_c_examples.py checks it).
//
// Build with nothing but pyoa's flags (docs/renderers.md):
//     c++ -std=c++14 -O2 $(python -m pyoa.config --cflags) examples/cpp/integrate7d.cpp -o integrate7d-cpp -lm
//     ./integrate7d-cpp [sampler [spp [seed]]]        (default: bose 49 0)
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include <pyoa/sampler.hpp>

namespace {

const int kWidth = 32, kHeight = 32, kDims = 7;

// A renderer's integer point type: StartPixelSample takes any type with .x and .y.
struct Point2i {
    int x, y;
};

double Integrand(const float x[kDims])
{
    double sum = 0.0;
    for (int j = 0; j < kDims; ++j)
        sum += (double(x[j]) - 0.5) * (double(x[j]) - 0.5);
    return std::exp(-sum);
}

double ExactIntegral()
{
    const double pi = 3.14159265358979323846;
    return std::pow(std::sqrt(pi) * std::erf(0.5), double(kDims));
}

// A sampler and the memory of its table (empty for samplers without one).
struct Owned {
    pyoa::Sampler sampler;
    std::vector<pyoa_u64> table;  // 8-byte aligned, as Create asks
};

bool Make(Owned &owned, const char *name, int spp, int seed)
{
    // The C program's options: pyoa.sampler(name, spp=spp, dims=7, seed=seed). A renderer that does not
    // know its dimension count calls Create(owned.sampler, name, spp, width, height, seed, allocate).
    pyoa_options options = pyoa_options_default(name, pyoa_u32(spp));
    options.dims = kDims;
    options.seed = pyoa_u32(seed);
    pyoa::Status status = pyoa::Sampler::Create(owned.sampler, options, kWidth, kHeight,
                                                [&owned](std::size_t bytes) {
                                                    owned.table.resize((bytes + 7) / 8);
                                                    return static_cast<void *>(owned.table.data());
                                                });
    if (!status.ok())
        std::fprintf(stderr, "integrate7d: %s\n", status.message);
    return status.ok();
}

// RMS over the pixels of (the pixel's estimate - the exact integral).
double RmsError(const pyoa::Sampler &prototype)
{
    const double exact = ExactIntegral();
    double sum = 0.0;
    for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) {
            pyoa::Sampler sampler = prototype.Clone();  // per thread (or GPU lane) in a renderer
            double estimate = 0.0;
            for (int i = 0; i < sampler.SamplesPerPixel(); ++i) {
                sampler.StartPixelSample(Point2i{x, y}, i);
                pyoa::Point2f film = sampler.GetPixel2D();
                float time = sampler.Get1D();
                pyoa::Point2f lens = sampler.Get2D();
                pyoa::Point2f light = sampler.Get2D();
                const float u[kDims] = {film.x, film.y, time, lens.x, lens.y, light.x, light.y};
                estimate += Integrand(u);
            }
            estimate /= sampler.SamplesPerPixel();
            sum += (estimate - exact) * (estimate - exact);
        }
    return std::sqrt(sum / (kWidth * kHeight));
}

bool ParseInt(const char *text, const char *what, int &out)
{
    char *end;
    errno = 0;
    long v = std::strtol(text, &end, 10);
    if (*text == '\0' || *end != '\0' || errno != 0 || v < -2147483647L - 1 || v > 2147483647L) {
        std::fprintf(stderr, "integrate7d: %s must be a 32-bit integer, not '%s'\n", what, text);
        return false;
    }
    out = int(v);
    return true;
}

}  // namespace

int main(int argc, char **argv)
{
    const char *name = argc > 1 ? argv[1] : "bose";
    int spp = 49, seed = 0;  // pbrt's types: the seed's 32 bits are pyoa's uint32 seed
    if (argc > 4) {
        std::fprintf(stderr, "usage: %s [sampler [spp [seed]]]\n", argv[0]);
        return 2;
    }
    if ((argc > 2 && !ParseInt(argv[2], "spp", spp)) || (argc > 3 && !ParseInt(argv[3], "seed", seed)))
        return 2;
    Owned s, r;
    if (!Make(s, name, spp, seed) || !Make(r, "random", spp, seed))
        return 1;
    const double errS = RmsError(s.sampler), errR = RmsError(r.sampler);
    std::printf("7D Genz Gaussian, exact integral %.6f; %d x %d pixels, %d spp, seed %u\n", ExactIntegral(), kWidth,
                kHeight, spp, unsigned(pyoa_u32(seed)));
    std::printf("%-8s RMS error %.3e\n", name, errS);
    std::printf("%-8s RMS error %.3e\n", "random", errR);
    std::printf("random / %s: %.1f\n", name, errR / errS);
    return 0;
}
