/* benchmarks/cuda/values.cu: pyoa's values on an NVIDIA GPU, from the
 * portable headers alone (kernels/include/pyoa/sampler.h), for
 * benchmarks/cuda_check.py (docs/renderers.md, "CUDA").
 *
 * Build with pyoa's flags and nothing else (what docs/renderers.md tells a
 * renderer; no flag is needed for bit-exactness):
 *
 *     nvcc -std=c++14 -O2 -I"$(python -m pyoa.config --include)" benchmarks/cuda/values.cu -o values
 *
 * Run:
 *
 *     values NAME SPP DIMS SEED PIXEL0 PIXELS OUT [options]
 *
 * makes sampler NAME (spp SPP, dims DIMS, seed SEED) on the host with
 * pyoa_sampler_make, fills its table (if it has one) in host memory, copies
 * the table to device memory (cudaMalloc + cudaMemcpy) and binds the device
 * copy (docs/renderers.md's recipe), then launches a kernel in which thread
 * k writes value k of the rectangle
 *
 *     pixels [PIXEL0, PIXEL0 + PIXELS) x samples [S0, S0 + NS) x dims [D0, D0 + ND)
 *
 * in pyoa's generate layout (pixels x samples x dims, float32, row-major:
 * k = ((p - PIXEL0) * NS + (i - S0)) * ND + (j - D0)), so that neighbouring
 * threads write neighbouring floats (coalesced stores). The values are
 * copied back and written to OUT as raw float32 (native byte order: little
 * endian on every CUDA host), which pyoa.Sampler.generate(pixels=range(PIXEL0,
 * PIXEL0 + PIXELS), samples=..., dims=...) gives bit for bit.
 *
 * Options:
 *   --samples S0 NS     the sample range (default: every sample, 0..spp)
 *   --dim-range D0 ND   the dimension range (default: 0..DIMS; required when DIMS is 0)
 *   --offset NAME       the OAs' offset style (cmj, mj, j, centered)
 *   --jitter F          the jitter amount (default 1)
 *   --strength T        an OA's strength (0: the sampler's default)
 *   --base B            faure's or zfaure's base (0: its default)
 *   --resolution W H    the image (zsobol, zfaure)
 *   --repeats R         timed launches after a warm-up (default 10; 0: one untimed launch)
 *   --host              compute the rectangle on the host instead (no CUDA call at all: the
 *                       tests run this where there is no GPU, to check the arguments, the layout
 *                       and the file against NumPy)
 *   --probe             print the device as JSON and exit
 *
 * Timing: the value kernel is timed with cudaEvents over R launches (median
 * and minimum; values/s and GB/s written). In the same process, before it,
 * the device's write bandwidth is measured two ways over the same number of
 * bytes: a kernel of the same shape that stores a constant (the best any
 * kernel with this store pattern can do) and cudaMemset. The fraction of
 * bandwidth is the value kernel's GB/s over the faster of the two: 1.0
 * means the kernel is bound by its stores, not by computing the values.
 *
 * stdout: one line of JSON (the device, the sizes, the timings).
 * Exit status: 0 done; 1 bad arguments or a sampler pyoa refuses (its
 * message, the Python API's, on stderr); 2 no usable CUDA device
 * (cudaGetDeviceCount fails or counts 0); 3 a CUDA call failed (which, where
 * and why on stderr); 4 the output file could not be written. */
#include <pyoa/sampler.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <cuda_runtime.h>

namespace {

/* Stop on any CUDA error with the call, the place and CUDA's reason. */
#define CHECK(call)                                                                                          \
    do {                                                                                                     \
        cudaError_t check_status_ = (call);                                                                  \
        if (check_status_ != cudaSuccess) {                                                                  \
            std::fprintf(stderr, "values: CUDA error: %s failed at %s:%d: %s (%s)\n", #call, __FILE__,       \
                         __LINE__, cudaGetErrorString(check_status_), cudaGetErrorName(check_status_));     \
            std::exit(3);                                                                                    \
        }                                                                                                    \
    } while (0)

const int kThreads = 256;

/* Value k of the rectangle (the layout above): the kernel's thread k and the host path (--host) both
 * call this, so the tests that run the host path check the kernel's indexing too. n < 2^32 (checked
 * on the host), so the index arithmetic is 32-bit. */
__host__ __device__ inline float rectangle_value(const pyoa_sampler *s, pyoa_u32 p0, pyoa_u32 s0, pyoa_u32 ns,
                                                 pyoa_u32 d0, pyoa_u32 nd, pyoa_u32 k)
{
    pyoa_u32 q = k / nd, j = k - q * nd; /* q = pixel * NS + sample */
    pyoa_u32 p = q / ns, i = q - p * ns;
    return pyoa_sampler_value(s, p0 + p, s0 + i, d0 + j);
}

/* Thread k writes value k; one value per thread, no loop: the grid covers the rectangle. */
__global__ void ValuesKernel(pyoa_sampler s, pyoa_u32 p0, pyoa_u32 s0, pyoa_u32 ns, pyoa_u32 d0, pyoa_u32 nd,
                             pyoa_u32 n, float *out)
{
    unsigned long long k64 = (unsigned long long)blockIdx.x * blockDim.x + threadIdx.x;
    if (k64 < n)
        out[k64] = rectangle_value(&s, p0, s0, ns, d0, nd, (pyoa_u32)k64);
}

/* The write-bandwidth reference: the same grid and stores, no values to compute. */
__global__ void WriteKernel(pyoa_u32 n, float v, float *out)
{
    unsigned long long k64 = (unsigned long long)blockIdx.x * blockDim.x + threadIdx.x;
    if (k64 < n)
        out[k64] = v;
}

void usage()
{
    std::fprintf(stderr,
                 "usage: values NAME SPP DIMS SEED PIXEL0 PIXELS OUT [--samples S0 NS] [--dim-range D0 ND]\n"
                 "              [--offset NAME] [--jitter F] [--strength T] [--base B] [--resolution W H]\n"
                 "              [--repeats R] [--host]\n"
                 "       values --probe\n");
}

/* A uint32 argument, or exit 1 naming it. */
pyoa_u32 u32_arg(const char *text, const char *what)
{
    char *end = NULL;
    errno = 0;
    unsigned long long v = std::strtoull(text, &end, 0);
    if (text[0] == '\0' || text[0] == '-' || *end != '\0' || errno != 0 || v > 0xFFFFFFFFull) {
        std::fprintf(stderr, "values: %s must be an integer in [0, 2^32), got '%s'\n", what, text);
        std::exit(1);
    }
    return (pyoa_u32)v;
}

float float_arg(const char *text, const char *what)
{
    char *end = NULL;
    double v = std::strtod(text, &end);
    if (text[0] == '\0' || *end != '\0') {
        std::fprintf(stderr, "values: %s must be a number, got '%s'\n", what, text);
        std::exit(1);
    }
    return (float)v;
}

/* A string for a JSON value: quotes and backslashes escaped, control characters dropped. */
std::string json_string(const char *text)
{
    std::string s = "\"";
    for (const char *c = text; *c != '\0'; ++c) {
        if (*c == '"' || *c == '\\')
            s += '\\';
        if ((unsigned char)*c >= 0x20)
            s += *c;
    }
    return s + "\"";
}

/* The first CUDA device, or exit 2: no driver, no device, or none visible. */
int require_device()
{
    int count = 0;
    cudaError_t e = cudaGetDeviceCount(&count);
    if (e != cudaSuccess || count == 0) {
        std::fprintf(stderr, "values: no CUDA device: cudaGetDeviceCount %s%s%s\n",
                     e != cudaSuccess ? "failed: " : "returned 0",
                     e != cudaSuccess ? cudaGetErrorName(e) : "",
                     e != cudaSuccess ? (std::string(" (") + cudaGetErrorString(e) + ")").c_str() : "");
        std::exit(2);
    }
    CHECK(cudaSetDevice(0));
    return count;
}

/* The device as the body of a JSON object (no braces). */
std::string device_json(int count)
{
    cudaDeviceProp prop;
    CHECK(cudaGetDeviceProperties(&prop, 0));
    int driver = 0, runtime = 0, clock_khz = 0, bus_bits = 0;
    CHECK(cudaDriverGetVersion(&driver));
    CHECK(cudaRuntimeGetVersion(&runtime));
    /* cudaDeviceProp lost memoryClockRate and memoryBusWidth in CUDA 13: ask for the attributes. */
    CHECK(cudaDeviceGetAttribute(&clock_khz, cudaDevAttrMemoryClockRate, 0));
    CHECK(cudaDeviceGetAttribute(&bus_bits, cudaDevAttrGlobalMemoryBusWidth, 0));
    /* DDR: two transfers per clock; a figure the measured bandwidth below is compared with. */
    double peak_gbs = 2.0 * clock_khz * 1e3 * (bus_bits / 8.0) / 1e9;
    char buf[1024];
    std::snprintf(buf, sizeof buf,
                  "\"device\": %s, \"device_count\": %d, \"compute_capability\": \"%d.%d\", \"sm_count\": %d, "
                  "\"global_memory_bytes\": %llu, \"memory_clock_khz\": %d, \"memory_bus_bits\": %d, "
                  "\"theoretical_gb_per_s\": %.6g, \"cuda_driver_version\": %d, \"cuda_runtime_version\": %d",
                  json_string(prop.name).c_str(), count, prop.major, prop.minor, prop.multiProcessorCount,
                  (unsigned long long)prop.totalGlobalMem, clock_khz, bus_bits, peak_gbs, driver, runtime);
    return buf;
}

struct Timing {
    double median_ms, min_ms;
};

/* Launch `launch` once (warm-up), then time it `repeats` times with events around each launch. */
template <class Launch>
Timing time_launches(Launch launch, int repeats)
{
    cudaEvent_t start, stop;
    CHECK(cudaEventCreate(&start));
    CHECK(cudaEventCreate(&stop));
    launch();
    CHECK(cudaGetLastError());
    CHECK(cudaDeviceSynchronize());
    std::vector<float> ms;
    for (int r = 0; r < repeats; ++r) {
        CHECK(cudaEventRecord(start));
        launch();
        CHECK(cudaGetLastError());
        CHECK(cudaEventRecord(stop));
        CHECK(cudaEventSynchronize(stop));
        float t = 0.0f;
        CHECK(cudaEventElapsedTime(&t, start, stop));
        ms.push_back(t);
    }
    CHECK(cudaEventDestroy(start));
    CHECK(cudaEventDestroy(stop));
    std::sort(ms.begin(), ms.end());
    Timing out = {0.0, 0.0};
    if (!ms.empty()) {
        size_t m = ms.size();
        out.median_ms = m % 2 ? ms[m / 2] : 0.5 * (ms[m / 2 - 1] + ms[m / 2]);
        out.min_ms = ms[0];
    }
    return out;
}

void write_file(const char *path, const float *values, size_t n)
{
    std::FILE *f = std::fopen(path, "wb");
    if (f == NULL || std::fwrite(values, sizeof(float), n, f) != n || std::fclose(f) != 0) {
        std::fprintf(stderr, "values: cannot write %zu floats to %s: %s\n", n, path, std::strerror(errno));
        std::exit(4);
    }
}

}  // namespace

int main(int argc, char **argv)
{
    if (argc == 2 && std::strcmp(argv[1], "--probe") == 0) {
        int count = require_device();
        std::printf("{%s}\n", device_json(count).c_str());
        return 0;
    }
    if (argc < 8) {
        usage();
        return 1;
    }
    pyoa_options o = pyoa_options_default(argv[1], u32_arg(argv[2], "SPP"));
    o.dims = u32_arg(argv[3], "DIMS");
    o.seed = u32_arg(argv[4], "SEED");
    const pyoa_u32 p0 = u32_arg(argv[5], "PIXEL0"), np = u32_arg(argv[6], "PIXELS");
    const char *path = argv[7];
    pyoa_u32 s0 = 0, ns = 0, d0 = 0, nd = o.dims;
    int samples_given = 0, repeats = 10, host = 0;
    for (int a = 8; a < argc; ++a) {
        const char *opt = argv[a];
        int left = argc - a - 1; /* arguments after this option */
        if (std::strcmp(opt, "--samples") == 0 && left >= 2) {
            s0 = u32_arg(argv[++a], "S0");
            ns = u32_arg(argv[++a], "NS");
            samples_given = 1;
        } else if (std::strcmp(opt, "--dim-range") == 0 && left >= 2) {
            d0 = u32_arg(argv[++a], "D0");
            nd = u32_arg(argv[++a], "ND");
        } else if (std::strcmp(opt, "--offset") == 0 && left >= 1) {
            o.offset = argv[++a];
        } else if (std::strcmp(opt, "--jitter") == 0 && left >= 1) {
            o.jitter = float_arg(argv[++a], "--jitter");
        } else if (std::strcmp(opt, "--strength") == 0 && left >= 1) {
            o.strength = u32_arg(argv[++a], "--strength");
        } else if (std::strcmp(opt, "--base") == 0 && left >= 1) {
            o.base = u32_arg(argv[++a], "--base");
        } else if (std::strcmp(opt, "--resolution") == 0 && left >= 2) {
            o.width = u32_arg(argv[++a], "W");
            o.height = u32_arg(argv[++a], "H");
        } else if (std::strcmp(opt, "--repeats") == 0 && left >= 1) {
            repeats = (int)u32_arg(argv[++a], "--repeats");
        } else if (std::strcmp(opt, "--host") == 0) {
            host = 1;
        } else {
            std::fprintf(stderr, "values: unknown option or missing argument: %s\n", opt);
            usage();
            return 1;
        }
    }

    pyoa_sampler s;
    char message[1024];
    if (pyoa_sampler_make(&s, &o, message, sizeof message) != PYOA_OK) {
        std::fprintf(stderr, "values: %s\n", message);
        return 1;
    }
    if (!samples_given)
        ns = s.spp;
    /* The rectangle must lie in the sampler's ranges (values outside are unspecified) and fit the
     * kernel's 32-bit index. */
    const unsigned long long n = (unsigned long long)np * ns * nd;
    const char *bad = NULL;
    if (np == 0 || ns == 0 || nd == 0)
        bad = "the rectangle is empty (PIXELS, NS and ND must be positive; give --dim-range when DIMS is 0)";
    else if ((unsigned long long)p0 + np > 0x100000000ull)
        bad = "PIXEL0 + PIXELS exceeds 2^32";
    else if ((unsigned long long)s0 + ns > s.spp)
        bad = "S0 + NS exceeds the sampler's spp";
    else if (o.dims != 0 && (unsigned long long)d0 + nd > o.dims)
        bad = "D0 + ND exceeds DIMS";
    else if (n >= 0x100000000ull)
        bad = "the rectangle has 2^32 values or more";
    if (bad != NULL) {
        std::fprintf(stderr, "values: %s\n", bad);
        return 1;
    }

    /* No device, no point in building a table (pmj02's takes a second or two): fail first. */
    const int count = host ? 0 : require_device();

    /* The table, filled in host memory (8-byte aligned, as pyoa_sampler_fill_table needs). */
    const size_t table_bytes = pyoa_sampler_table_bytes(&s);
    std::vector<unsigned long long> host_table((table_bytes + 7) / 8);
    std::vector<float> values((size_t)n);
    if (table_bytes != 0) {
        pyoa_sampler_fill_table(&s, host_table.data());
        pyoa_sampler_bind_table(&s, host_table.data());
    }

    if (host) { /* the same rectangle from the host table: pyoa_sampler_value is __host__ __device__ */
        auto t0 = std::chrono::steady_clock::now();
        for (pyoa_u32 k = 0; k < (pyoa_u32)n; ++k)
            values[k] = rectangle_value(&s, p0, s0, ns, d0, nd, k);
        double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        write_file(path, values.data(), values.size());
        std::printf("{\"mode\": \"host\", \"sampler\": %s, \"spp\": %u, \"dims\": %u, \"seed\": %u, "
                    "\"values\": %llu, \"table_bytes\": %zu, \"host_ms\": %.6g}\n",
                    json_string(argv[1]).c_str(), s.spp, o.dims, o.seed, n, table_bytes, ms);
        return 0;
    }

    const std::string device = device_json(count);
    /* docs/renderers.md's recipe: copy the filled table to device memory, bind the copy. */
    void *device_table = NULL;
    if (table_bytes != 0) {
        CHECK(cudaMalloc(&device_table, table_bytes)); /* 256-byte aligned */
        CHECK(cudaMemcpy(device_table, host_table.data(), table_bytes, cudaMemcpyHostToDevice));
        pyoa_sampler_bind_table(&s, device_table); /* from here on s is for device code only */
    }
    const size_t bytes = (size_t)n * sizeof(float);
    float *device_values = NULL;
    CHECK(cudaMalloc(&device_values, bytes));
    const unsigned blocks = (unsigned)((n + kThreads - 1) / kThreads);
    const pyoa_u32 n32 = (pyoa_u32)n;

    /* The write bandwidth first (these overwrite the buffer the values go to). */
    const int bw_repeats = repeats > 0 ? repeats : 1;
    Timing write = time_launches([&] { WriteKernel<<<blocks, kThreads>>>(n32, 0.5f, device_values); },
                                 bw_repeats);
    Timing memset = time_launches([&] { CHECK(cudaMemsetAsync(device_values, 0, bytes)); }, bw_repeats);
    /* 0xFFFFFFFF, a NaN no sampler gives: a value the kernel failed to write shows as a mismatch. */
    CHECK(cudaMemset(device_values, 0xFF, bytes));
    CHECK(cudaDeviceSynchronize());
    Timing kernel = {0.0, 0.0};
    if (repeats > 0) {
        kernel = time_launches([&] {
            ValuesKernel<<<blocks, kThreads>>>(s, p0, s0, ns, d0, nd, n32, device_values);
        }, repeats);
    } else {
        ValuesKernel<<<blocks, kThreads>>>(s, p0, s0, ns, d0, nd, n32, device_values);
        CHECK(cudaGetLastError());
        CHECK(cudaDeviceSynchronize());
    }
    CHECK(cudaMemcpy(values.data(), device_values, bytes, cudaMemcpyDeviceToHost));
    CHECK(cudaFree(device_values));
    if (device_table != NULL)
        CHECK(cudaFree(device_table));
    write_file(path, values.data(), values.size());

    const double gb = bytes / 1e9;
    auto rate = [](double amount, double ms) { return ms > 0.0 ? amount / (ms * 1e-3) : 0.0; };
    const double write_gbs = rate(gb, write.median_ms), memset_gbs = rate(gb, memset.median_ms);
    const double bandwidth = std::max(write_gbs, memset_gbs), kernel_gbs = rate(gb, kernel.median_ms);
    std::printf("{\"mode\": \"cuda\", \"sampler\": %s, \"spp\": %u, \"dims\": %u, \"seed\": %u, "
                "\"pixel0\": %u, \"pixels\": %u, \"sample0\": %u, \"samples\": %u, \"dim0\": %u, \"dim_count\": %u, "
                "\"values\": %llu, \"bytes\": %zu, \"table_bytes\": %zu, \"repeats\": %d, \"threads_per_block\": %d, "
                "\"kernel_ms_median\": %.6g, \"kernel_ms_min\": %.6g, \"values_per_s\": %.6g, \"gb_per_s\": %.6g, "
                "\"write_kernel_ms_median\": %.6g, \"write_kernel_gb_per_s\": %.6g, "
                "\"memset_ms_median\": %.6g, \"memset_gb_per_s\": %.6g, \"bandwidth_gb_per_s\": %.6g, "
                "\"fraction_of_bandwidth\": %.6g, %s}\n",
                json_string(argv[1]).c_str(), s.spp, o.dims, o.seed, p0, np, s0, ns, d0, nd, n, bytes, table_bytes,
                repeats, kThreads, kernel.median_ms, kernel.min_ms, rate((double)n, kernel.median_ms), kernel_gbs,
                write.median_ms, write_gbs, memset.median_ms, memset_gbs, bandwidth,
                bandwidth > 0.0 ? kernel_gbs / bandwidth : 0.0, device.c_str());
    return 0;
}
