// SPDX-License-Identifier: MIT
//
// pyoa's C header samplers against OpenQMC, in one C++17 process: ns per value.
//
// Built and run by benchmarks/bench_openqmc.py (see benchmarks/README.md,
// "OpenQMC: bench_openqmc.py"); by hand:
//
//   g++ -std=c++17 -O2 -march=native -DNDEBUG -I "$(python -c 'import pyoa; print(pyoa.get_include())')"
//       -I /path/to/openqmc/include benchmarks/openqmc/bench.cpp -o /tmp/bench_openqmc   (one line)
//   /tmp/bench_openqmc --rounds 11          # JSON on stdout
//
// What is timed (every case draws every value of a width x height image, spp
// samples per pixel, dims dimensions, and folds it into a checksum):
//
// - "scalar": one value at a time, as a renderer asks for them: a pixel loop
//   (y, x), a sample loop and a dimension loop. pyoa: pyoa_sampler_value(s,
//   pixel, sample, dim) per value. OpenQMC: one sampler object per (pixel,
//   sample), SamplerInterface(x, y, 0, sample, cache), one domain per group of
//   K dimensions, base.newDomain(d), and drawSample<K>(float[K]) with K = 1
//   (one value per call, as pyoa), 2 (a 2D point per call, OpenQMC's README
//   usage) or 4 (its maximum, what its own benchmark tool draws; 10 dimensions
//   are then draws of 4, 4 and 2). Each value's bits are xor-ed into one
//   accumulator that an empty asm statement pins in a register after every
//   value, so the compiler can neither drop a value nor vectorize the loop:
//   the values are independent (out-of-order execution overlaps them), but
//   they are computed one at a time.
// - "lanes": the same values, with the innermost loop over LANES consecutive
//   pixels of one raster row for one (sample, dimension) (pyoa) or one
//   (sample, domain) (OpenQMC: LANES sampler objects, one per pixel, built
//   once per sample), xor-ed into LANES accumulators: a loop the compiler may
//   vectorize. Whether it did is read by the driver from the compiler's
//   vectorizer report (GCC -fopt-info-vec-all, Clang -Rpass=loop-vectorize;
//   a template's loop compiled alone per instantiation with
//   -DBENCH_VEC_PROBE_*) and shows in the timing.
//
// - "fill" and "prepared" (pyoa's orthogonal arrays only): a pixel's values at
//   once through pyoa/fill.h, the bulk path for CPU renderers: "fill" calls
//   pyoa_sampler_fill(s, pixel, 0, spp, 0, dims, buf, scratch) per pixel
//   (stateless: everything that does not depend on the pixel, the cells of
//   the array, is recomputed for every pixel); "prepared" calls
//   pyoa_fill_prepare(s, 0, spp, 0, dims, scratch) once per image and then
//   pyoa_fill_pixel(scratch, pixel, buf) per pixel, as a renderer's pixel loop
//   would. The spp x dims values of each pixel are xor-ed into one accumulator
//   (pinned after each pixel). The values are pyoa_sampler_value's, bit for
//   bit (checked with --check, like the others).
//
// Rounds: every case runs once untimed (warm-up, first-touch of tables), then
// --rounds rounds; round r runs all cases in the order of interleave() (the
// headline pairs back to back, then pyoa's and OpenQMC's cases mixed)
// rotated by r, so a slow spell of the shared machine is spread over both.
// Each case's time per round is this thread's CPU time
// (CLOCK_THREAD_CPUTIME_ID; see cpuNs) around one full-image call; ns per
// value = that / (width height spp dims). The wall time (steady_clock) is
// recorded beside it.
//
// Build switches: -DBENCH_LANES=16 (default) sets the lane count;
// -DBENCH_NO_PYOA builds the OpenQMC side alone (pyoa's cases are then
// absent); -DBENCH_VEC_PROBE_PYOA, or -DBENCH_VEC_PROBE_OQMC=oqmc::PmjSampler
// with -DBENCH_VEC_PROBE_K=2, make main() reference that one lane kernel and
// nothing else, so that the vectorizer's messages at the "vec-probe" lines
// are that kernel's (compile-only use, by the driver).

#include <oqmc/oqmc.h>

#ifndef BENCH_NO_PYOA
#include <pyoa/fill.h>
#include <pyoa/sampler.h>
#endif

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <functional>
#include <string>
#include <vector>

#ifndef BENCH_LANES
#define BENCH_LANES 16
#endif

namespace
{

constexpr int LANES = BENCH_LANES;

// Keep `x` in a register here: later values cannot be merged with earlier ones
// into vector operations, and nothing computed into `x` can be dropped.
#define BENCH_SINK(x) __asm__("" : "+r"(x))

inline std::uint32_t bits(float v)
{
	std::uint32_t u;
	std::memcpy(&u, &v, sizeof u);
	return u;
}

struct Image
{
	int width, height, spp, dims;
	double values() const { return double(width) * height * spp * dims; }
};

// ---------------------------------------------------------------------------
// OpenQMC

// Draw n <= 4 values (n known only at run time: the tail of a dimension loop
// whose length is not a multiple of K).
template <class S>
inline void drawN(const S& dom, int n, float* v)
{
	switch(n)
	{
	case 1: dom.template drawSample<1>(v); break;
	case 2: dom.template drawSample<2>(v); break;
	case 3: dom.template drawSample<3>(v); break;
	default: dom.template drawSample<4>(v); break;
	}
}

template <class S, int K>
__attribute__((noinline)) std::uint32_t oqmcScalar(const void* cache, Image g)
{
	std::uint32_t acc = 0;
	const int full = g.dims - g.dims % K;
	for(int y = 0; y < g.height; ++y)
		for(int x = 0; x < g.width; ++x)
			for(int i = 0; i < g.spp; ++i)
			{
				const S base(x, y, 0, i, cache);
				int d = 0;
				for(; d < full; d += K)
				{
					float v[K];
					base.newDomain(d).template drawSample<K>(v);
					for(int k = 0; k < K; ++k)
					{
						acc ^= bits(v[k]);
						BENCH_SINK(acc);
					}
				}
				if(d < g.dims)
				{
					float v[4];
					const int n = g.dims - d;
					drawN(base.newDomain(d), n, v);
					for(int k = 0; k < n; ++k)
					{
						acc ^= bits(v[k]);
						BENCH_SINK(acc);
					}
				}
			}
	return acc;
}

template <class S, int K>
__attribute__((noinline)) std::uint32_t oqmcLanes(const void* cache, Image g)
{
	std::uint32_t acc[LANES] = {};
	const int full = g.dims - g.dims % K;
	for(int y = 0; y < g.height; ++y)
		for(int x0 = 0; x0 < g.width; x0 += LANES)
			for(int i = 0; i < g.spp; ++i)
			{
				S base[LANES];
				for(int lane = 0; lane < LANES; ++lane) // vec-probe: init
					base[lane] = S(x0 + lane, y, 0, i, cache);
				int d = 0;
				for(; d < full; d += K)
					for(int lane = 0; lane < LANES; ++lane) // vec-probe: draw
					{
						float v[K];
						base[lane].newDomain(d).template drawSample<K>(v);
						for(int k = 0; k < K; ++k)
							acc[lane] ^= bits(v[k]);
					}
				if(d < g.dims)
				{
					const int n = g.dims - d;
					for(int lane = 0; lane < LANES; ++lane) // vec-probe: tail
					{
						float v[4];
						drawN(base[lane].newDomain(d), n, v);
						for(int k = 0; k < n; ++k)
							acc[lane] ^= bits(v[k]);
					}
				}
			}
	std::uint32_t out = 0;
	for(int lane = 0; lane < LANES; ++lane)
		out ^= acc[lane];
	return out;
}

// Mean of every value (the --check output: near 0.5 for a working sampler).
template <class S>
double oqmcMean(const void* cache, Image g)
{
	double sum = 0.0;
	for(int y = 0; y < g.height; ++y)
		for(int x = 0; x < g.width; ++x)
			for(int i = 0; i < g.spp; ++i)
			{
				const S base(x, y, 0, i, cache);
				for(int d = 0; d < g.dims; d += 4)
				{
					float v[4];
					const int n = g.dims - d < 4 ? g.dims - d : 4;
					drawN(base.newDomain(d), n, v);
					for(int k = 0; k < n; ++k)
						sum += v[k];
				}
			}
	return sum / g.values();
}

// ---------------------------------------------------------------------------
// pyoa

#ifndef BENCH_NO_PYOA
__attribute__((noinline)) std::uint32_t pyoaScalar(const pyoa_sampler* sp, Image g)
{
	const pyoa_sampler s = *sp; // by value, as a renderer passes it to a kernel
	std::uint32_t acc = 0;
	for(int y = 0; y < g.height; ++y)
		for(int x = 0; x < g.width; ++x)
		{
			const pyoa_u32 pixel = pyoa_pixel_index(pyoa_u32(x), pyoa_u32(y), pyoa_u32(g.width));
			for(int i = 0; i < g.spp; ++i)
				for(int d = 0; d < g.dims; ++d)
				{
					acc ^= bits(pyoa_sampler_value(&s, pixel, pyoa_u32(i), pyoa_u32(d)));
					BENCH_SINK(acc);
				}
		}
	return acc;
}

__attribute__((noinline)) std::uint32_t pyoaLanes(const pyoa_sampler* sp, Image g)
{
	const pyoa_sampler s = *sp;
	std::uint32_t acc[LANES] = {};
	for(int y = 0; y < g.height; ++y)
		for(int x0 = 0; x0 < g.width; x0 += LANES)
		{
			const pyoa_u32 pixel0 = pyoa_pixel_index(pyoa_u32(x0), pyoa_u32(y), pyoa_u32(g.width));
			for(int i = 0; i < g.spp; ++i)
				for(int d = 0; d < g.dims; ++d)
					for(int lane = 0; lane < LANES; ++lane) // vec-probe: draw
						acc[lane] ^= bits(pyoa_sampler_value(&s, pixel0 + pyoa_u32(lane), pyoa_u32(i), pyoa_u32(d)));
		}
	std::uint32_t out = 0;
	for(int lane = 0; lane < LANES; ++lane)
		out ^= acc[lane];
	return out;
}

// The bulk path (pyoa/fill.h): one pyoa_sampler_fill call per pixel, its
// spp x dims values folded by xor (a loop the compiler vectorizes).
inline std::uint32_t foldBits(const float* v, pyoa_u32 n)
{
	std::uint32_t a = 0;
	for(pyoa_u32 k = 0; k < n; ++k)
		a ^= bits(v[k]);
	return a;
}

__attribute__((noinline)) std::uint32_t pyoaFill(const pyoa_sampler* sp, void* scratch, float* buf, Image g)
{
	const pyoa_sampler s = *sp;
	const pyoa_u32 spp = pyoa_u32(g.spp), dims = pyoa_u32(g.dims);
	std::uint32_t acc = 0;
	for(int y = 0; y < g.height; ++y)
		for(int x = 0; x < g.width; ++x)
		{
			const pyoa_u32 pixel = pyoa_pixel_index(pyoa_u32(x), pyoa_u32(y), pyoa_u32(g.width));
			pyoa_sampler_fill(&s, pixel, 0u, spp, 0u, dims, buf, scratch);
			acc ^= foldBits(buf, spp * dims);
			BENCH_SINK(acc);
		}
	return acc;
}

// The same with the pixel-independent work done once per image
// (pyoa_fill_prepare), then pyoa_fill_pixel per pixel.
__attribute__((noinline)) std::uint32_t pyoaFillPrepared(const pyoa_sampler* sp, void* scratch, float* buf, Image g)
{
	const pyoa_u32 spp = pyoa_u32(g.spp), dims = pyoa_u32(g.dims);
	std::uint32_t acc = 0;
	pyoa_fill_prepare(sp, 0u, spp, 0u, dims, scratch);
	for(int y = 0; y < g.height; ++y)
		for(int x = 0; x < g.width; ++x)
		{
			pyoa_fill_pixel(scratch, pyoa_pixel_index(pyoa_u32(x), pyoa_u32(y), pyoa_u32(g.width)), buf);
			acc ^= foldBits(buf, spp * dims);
			BENCH_SINK(acc);
		}
	return acc;
}
#endif

// ---------------------------------------------------------------------------
// cases

struct Case
{
	std::string name;    // e.g. "pyoa/bose/scalar", "openqmc/pmj/scalar/2"
	std::string library; // "pyoa" or "openqmc"
	std::string sampler; // pyoa's catalogue name or OpenQMC's header name
	std::string shape;   // "scalar", "lanes", or pyoa's "fill" and "prepared"
	int perDraw;         // values per call: 1 for pyoa (spp x dims for fill), K for OpenQMC
	Image image;
	std::function<std::uint32_t()> run;
	std::function<double()> mean;
	std::uint32_t checksum = 0;
	double setupNs = 0.0;   // OpenQMC: initialiseCache; pyoa: make + fill_table + bind_table
	double cacheBytes = 0.0; // OpenQMC cacheSize; pyoa table_bytes
	std::string params;     // what was made (pyoa: the sampler's resolved code and spp)
	std::vector<double> nsPerValue;     // thread CPU time per value, one entry per round
	std::vector<double> wallNsPerValue; // wall time per value (steady_clock)
};

double nowNs()
{
	using namespace std::chrono;
	return double(duration_cast<nanoseconds>(steady_clock::now().time_since_epoch()).count());
}

// CPU time of this thread (POSIX CLOCK_THREAD_CPUTIME_ID): what the case
// cost while it ran. On a machine shared with other work the wall time of
// a long call (pyoa's, ~50 ms) always includes time slices given to other
// processes while a short one (OpenQMC's, ~3 ms) often escapes them, which
// would bias every ratio; the thread's CPU time does not count them.
double cpuNs()
{
	timespec t;
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
	return double(t.tv_sec) * 1e9 + double(t.tv_nsec);
}

struct Options
{
	int width = 16, height = 16, rounds = 21, dims = 10, oqmcSpp = 121;
	unsigned seed = 0;
	bool check = false;
	std::string only; // comma-separated name prefixes
};

// Caches are allocated once and outlive the cases (kept in this list).
std::vector<std::vector<unsigned char>> storage;

void* allocate(std::size_t bytes)
{
	storage.emplace_back(bytes + 64);
	auto p = reinterpret_cast<std::uintptr_t>(storage.back().data());
	return reinterpret_cast<void*>((p + 63) & ~std::uintptr_t(63)); // 64-byte aligned
}

template <class S>
void addOpenqmc(std::vector<Case>& cases, const char* name, const Options& o)
{
	void* cache = S::cacheSize ? allocate(S::cacheSize) : nullptr;
	const double t0 = nowNs();
	S::initialiseCache(cache);
	const double setup = nowNs() - t0;
	const Image g{o.width, o.height, o.oqmcSpp, o.dims};
	auto add = [&](const char* shape, int k, std::function<std::uint32_t()> run) {
		Case c;
		c.name = std::string("openqmc/") + name + "/" + shape + "/" + std::to_string(k);
		c.library = "openqmc";
		c.sampler = name;
		c.shape = shape;
		c.perDraw = k;
		c.image = g;
		c.run = run;
		c.mean = [cache, g]() { return oqmcMean<S>(cache, g); };
		c.setupNs = setup;
		c.cacheBytes = double(S::cacheSize);
		cases.push_back(c);
	};
	add("scalar", 1, [cache, g]() { return oqmcScalar<S, 1>(cache, g); });
	add("scalar", 2, [cache, g]() { return oqmcScalar<S, 2>(cache, g); });
	add("scalar", 4, [cache, g]() { return oqmcScalar<S, 4>(cache, g); });
	add("lanes", 1, [cache, g]() { return oqmcLanes<S, 1>(cache, g); });
	add("lanes", 2, [cache, g]() { return oqmcLanes<S, 2>(cache, g); });
	add("lanes", 4, [cache, g]() { return oqmcLanes<S, 4>(cache, g); });
}

#ifndef BENCH_NO_PYOA
struct PyoaSpec
{
	const char* name;
	pyoa_u32 spp, strength;
	const char* offset;
};

// The pyoa cases: Bose cmj at 121 spp is the required case; the
// others at their nearest valid count (strength-3 arrays need s^3; pmj02 and
// sobol a power of two).
const PyoaSpec pyoaSpecs[] = {
    {"bose", 121, 0, "cmj"}, {"cmjnd", 125, 3, "cmj"}, {"bush", 125, 3, "cmj"},
    {"faure", 121, 0, nullptr}, {"pmj02", 128, 0, nullptr}, {"sobol", 128, 0, nullptr},
};

pyoa_sampler* makePyoa(const PyoaSpec& p, const Options& o, double* setup, double* bytes)
{
	auto s = static_cast<pyoa_sampler*>(allocate(sizeof(pyoa_sampler)));
	char message[512] = {0};
	const double t0 = nowNs();
	pyoa_options opt = pyoa_options_default(p.name, p.spp);
	opt.dims = pyoa_u32(o.dims); // as Python's pyoa.sampler(..., dims=10): sobol's table then holds 10 dimensions
	opt.seed = o.seed;
	opt.offset = p.offset;
	opt.strength = p.strength;
	const int err = pyoa_sampler_make(s, &opt, message, sizeof message);
	if(err != PYOA_OK)
	{
		std::fprintf(stderr, "pyoa_sampler_make(\"%s\", %u): error %d: %s\n", p.name, p.spp, err, message);
		std::exit(2);
	}
	const std::size_t tb = pyoa_sampler_table_bytes(s);
	if(tb)
	{
		void* table = allocate(tb);
		pyoa_sampler_fill_table(s, table);
		pyoa_sampler_bind_table(s, table);
	}
	*setup = nowNs() - t0;
	*bytes = double(tb);
	return s;
}

double pyoaMean(const pyoa_sampler* s, Image g)
{
	double sum = 0.0;
	for(int p = 0; p < g.width * g.height; ++p)
		for(int i = 0; i < g.spp; ++i)
			for(int d = 0; d < g.dims; ++d)
				sum += pyoa_sampler_value(s, pyoa_u32(p), pyoa_u32(i), pyoa_u32(d));
	return sum / g.values();
}

void addPyoa(std::vector<Case>& cases, const PyoaSpec& p, const Options& o)
{
	double setup = 0.0, bytes = 0.0;
	const pyoa_sampler* s = makePyoa(p, o, &setup, &bytes);
	const Image g{o.width, o.height, int(s->spp), o.dims};
	auto add = [&](const char* shape, std::function<std::uint32_t()> run) {
		Case c;
		c.name = std::string("pyoa/") + p.name + "/" + shape;
		c.library = "pyoa";
		c.sampler = p.name;
		c.shape = shape;
		c.perDraw = 1;
		c.image = g;
		c.run = run;
		c.mean = [s, g]() { return pyoaMean(s, g); };
		c.setupNs = setup;
		c.cacheBytes = bytes;
		c.params = std::string("spp=") + std::to_string(p.spp) + " strength=" + std::to_string(p.strength) +
		           " offset=" + (p.offset ? p.offset : "default") + " code=" + std::to_string(s->code);
		cases.push_back(c);
	};
	add("scalar", [s, g]() { return pyoaScalar(s, g); });
	add("lanes", [s, g]() { return pyoaLanes(s, g); });
	if(pyoa_fill_has_tables(s)) // the bulk path has tables for these; the others fall back to the value function
	{
		void* scratch = allocate(pyoa_fill_scratch_bytes(s, pyoa_u32(g.dims)));
		float* buf = static_cast<float*>(allocate(sizeof(float) * std::size_t(g.spp) * std::size_t(g.dims)));
		add("fill", [s, scratch, buf, g]() { return pyoaFill(s, scratch, buf, g); });
		add("prepared", [s, scratch, buf, g]() { return pyoaFillPrepared(s, scratch, buf, g); });
		cases[cases.size() - 2].perDraw = cases[cases.size() - 1].perDraw = g.spp * g.dims;
	}
}

// --check: the bits of pixels 0, 1 and width + 3, every sample and dimension,
// for the driver to compare with pyoa's Python API (the benchmark must time
// the values pyoa documents, not something else).
void printCheckBits(const pyoa_sampler* s, const PyoaSpec& p, const Options& o, bool first)
{
	const pyoa_u32 pixels[3] = {0u, 1u, pyoa_u32(o.width + 3)};
	std::printf("%s    {\"sampler\": \"%s\", \"spp\": %u, \"strength\": %u, \"offset\": %s%s%s, \"dims\": %d, "
	            "\"seed\": %u, \"pixels\": [%u, %u, %u], \"bits\": [",
	            first ? "" : ",\n", p.name, s->spp, p.strength, p.offset ? "\"" : "", p.offset ? p.offset : "null",
	            p.offset ? "\"" : "", o.dims, o.seed, pixels[0], pixels[1], pixels[2]);
	bool sep = false;
	for(pyoa_u32 p : pixels)
		for(pyoa_u32 i = 0; i < s->spp; ++i)
			for(int d = 0; d < o.dims; ++d)
			{
				std::printf("%s%u", sep ? ", " : "", bits(pyoa_sampler_value(s, p, i, pyoa_u32(d))));
				sep = true;
			}
	// the same values through the bulk path (pyoa/fill.h): pyoa_sampler_fill per
	// pixel, then pyoa_fill_pixel on a prepared plan
	std::vector<unsigned char> scratch(pyoa_fill_scratch_bytes(s, pyoa_u32(o.dims)) + 8);
	void* sc = reinterpret_cast<void*>((reinterpret_cast<std::uintptr_t>(scratch.data()) + 7) & ~std::uintptr_t(7));
	std::vector<float> buf(std::size_t(s->spp) * std::size_t(o.dims));
	for(int prepared = 0; prepared < 2; ++prepared)
	{
		std::printf("], \"%s\": [", prepared ? "prepared_bits" : "fill_bits");
		sep = false;
		if(prepared)
			pyoa_fill_prepare(s, 0u, s->spp, 0u, pyoa_u32(o.dims), sc);
		for(pyoa_u32 p : pixels)
		{
			if(prepared)
				pyoa_fill_pixel(sc, p, buf.data());
			else
				pyoa_sampler_fill(s, p, 0u, s->spp, 0u, pyoa_u32(o.dims), buf.data(), sc);
			for(float v : buf)
			{
				std::printf("%s%u", sep ? ", " : "", bits(v));
				sep = true;
			}
		}
	}
	std::printf("]}");
}
#endif

bool selected(const std::string& name, const std::string& only)
{
	if(only.empty())
		return true;
	std::size_t a = 0;
	while(a <= only.size())
	{
		std::size_t b = only.find(',', a);
		if(b == std::string::npos)
			b = only.size();
		const std::string prefix = only.substr(a, b - a);
		if(!prefix.empty() && name.compare(0, prefix.size(), prefix) == 0)
			return true;
		a = b + 1;
	}
	return false;
}

void jsonString(const std::string& s)
{
	std::putchar('"');
	for(char c : s)
	{
		if(c == '"' || c == '\\')
			std::putchar('\\');
		std::putchar(c);
	}
	std::putchar('"');
}

// The order of a round: the headline pairs first, each pyoa case right
// before an OpenQMC PMJ case (their per-round ratio then compares times
// taken a fraction of a second apart; Bose's fill cases sit beside PMJ's
// other draws, as each OpenQMC case appears once), then the other cases with
// pyoa's and OpenQMC's evenly mixed. Rounds rotate this order by one case.
std::vector<Case> interleave(const std::vector<Case>& in)
{
	const char* pairs[][2] = {{"pyoa/bose/scalar", "openqmc/pmj/scalar/2"},
	                          {"pyoa/bose/lanes", "openqmc/pmj/lanes/2"},
	                          {"pyoa/bose/fill", "openqmc/pmj/scalar/1"},
	                          {"pyoa/bose/prepared", "openqmc/pmj/scalar/4"}};
	std::vector<Case> out, a, b;
	std::vector<bool> used(in.size(), false);
	auto find = [&](const char* name) -> int {
		for(std::size_t k = 0; k < in.size(); ++k)
			if(!used[k] && in[k].name == name)
				return int(k);
		return -1;
	};
	for(auto& pair : pairs)
	{
		const int x = find(pair[0]), y = find(pair[1]);
		if(x < 0 || y < 0)
			continue;
		used[std::size_t(x)] = used[std::size_t(y)] = true;
		out.push_back(in[std::size_t(x)]);
		out.push_back(in[std::size_t(y)]);
	}
	for(std::size_t k = 0; k < in.size(); ++k)
		if(!used[k])
			(in[k].library == "pyoa" ? a : b).push_back(in[k]);
	std::size_t i = 0, j = 0; // merge: take from the list that is less far along
	while(i < a.size() || j < b.size())
		if(j >= b.size() || (i < a.size() && i * b.size() <= j * a.size()))
			out.push_back(a[i++]);
		else
			out.push_back(b[j++]);
	return out;
}

int usage()
{
	std::fprintf(stderr, "usage: bench [--width W] [--height H] [--rounds R] [--dims D] [--openqmc-spp N] "
	                     "[--seed S] [--only PREFIX,...] [--check]\n");
	return 2;
}

} // namespace

int main(int argc, char** argv)
{
#if defined(BENCH_VEC_PROBE_PYOA) || defined(BENCH_VEC_PROBE_OQMC)
	// Vectorization probe: the one lane kernel named, nothing else instantiated.
#if defined(BENCH_VEC_PROBE_PYOA)
	std::uint32_t (*volatile kernel)(const pyoa_sampler*, Image) = &pyoaLanes;
#else
	std::uint32_t (*volatile kernel)(const void*, Image) = &oqmcLanes<BENCH_VEC_PROBE_OQMC, BENCH_VEC_PROBE_K>;
#endif
	(void)kernel;
	(void)argc;
	(void)argv;
	return 0;
#else
	Options o;
	for(int a = 1; a < argc; ++a)
	{
		const std::string arg = argv[a];
		auto next = [&]() -> const char* {
			if(a + 1 >= argc)
				std::exit(usage());
			return argv[++a];
		};
		if(arg == "--width") o.width = std::atoi(next());
		else if(arg == "--height") o.height = std::atoi(next());
		else if(arg == "--rounds") o.rounds = std::atoi(next());
		else if(arg == "--dims") o.dims = std::atoi(next());
		else if(arg == "--openqmc-spp") o.oqmcSpp = std::atoi(next());
		else if(arg == "--seed") o.seed = unsigned(std::strtoul(next(), nullptr, 10));
		else if(arg == "--only") o.only = next();
		else if(arg == "--check") o.check = true;
		else return usage();
	}
	if(o.width <= 0 || o.width % LANES || o.height <= 0 || o.width > 256 || o.height > 256 || o.rounds < 1 ||
	   o.dims < 1 || o.oqmcSpp < 1)
	{
		// OpenQMC encodes 8 bits of x and y (State64Bit): larger images repeat its pixels.
		std::fprintf(stderr, "need 0 < width <= 256 (a multiple of %d), 0 < height <= 256, rounds >= 1, "
		                     "dims >= 1, openqmc-spp >= 1\n", LANES);
		return 2;
	}

	std::vector<Case> all;
#ifndef BENCH_NO_PYOA
	for(const PyoaSpec& p : pyoaSpecs)
		addPyoa(all, p, o);
#endif
	addOpenqmc<oqmc::PmjSampler>(all, "pmj", o);
	addOpenqmc<oqmc::PmjBnSampler>(all, "pmjbn", o);
	addOpenqmc<oqmc::SobolSampler>(all, "sobol", o);
	addOpenqmc<oqmc::SobolBnSampler>(all, "sobolbn", o);
	addOpenqmc<oqmc::LatticeSampler>(all, "lattice", o);
	addOpenqmc<oqmc::LatticeBnSampler>(all, "latticebn", o);

	std::vector<Case> cases;
	for(const Case& c : all)
		if(selected(c.name, o.only))
			cases.push_back(c);
	if(cases.empty())
	{
		std::fprintf(stderr, "--only %s selects no case\n", o.only.c_str());
		return 2;
	}

	if(o.check)
	{
		std::printf("{\"check\": [\n");
		bool first = true;
#ifndef BENCH_NO_PYOA
		for(const PyoaSpec& p : pyoaSpecs)
		{
			double setup, bytes;
			printCheckBits(makePyoa(p, o, &setup, &bytes), p, o, first);
			first = false;
		}
#endif
		std::printf("\n  ],\n  \"means\": {");
		first = true;
		for(const Case& c : cases)
		{
			if(c.shape != "scalar" || c.perDraw > 1)
				continue; // one mean per sampler
			std::printf("%s", first ? "" : ", ");
			jsonString(c.library + "/" + c.sampler);
			std::printf(": %.6f", c.mean());
			first = false;
		}
		std::printf("}\n}\n");
		return 0;
	}

	cases = interleave(cases);
	// Warm-up: every case once (tables into cache, pages touched, clocks up).
	for(Case& c : cases)
		c.checksum = c.run();
	const std::size_t n = cases.size();
	for(int r = 0; r < o.rounds; ++r)
		for(std::size_t k = 0; k < n; ++k)
		{
			Case& c = cases[(k + std::size_t(r)) % n];
			const double w0 = nowNs(), t0 = cpuNs();
			const std::uint32_t sum = c.run();
			const double dt = cpuNs() - t0, wall = nowNs() - w0;
			if(sum != c.checksum)
			{
				std::fprintf(stderr, "%s: checksum changed between runs (%u, %u)\n", c.name.c_str(), c.checksum,
				             sum);
				return 1;
			}
			c.nsPerValue.push_back(dt / c.image.values());
			c.wallNsPerValue.push_back(wall / c.image.values());
		}

	std::printf("{\n  \"lanes\": %d,\n  \"width\": %d,\n  \"height\": %d,\n  \"rounds\": %d,\n  \"seed\": %u,\n",
	            LANES, o.width, o.height, o.rounds, o.seed);
	std::printf("  \"compiler\": ");
	jsonString(__VERSION__);
	std::printf(",\n  \"openqmc_arch\": \"%s\",\n",
#if defined(OQMC_ARCH_AVX)
	            "AVX"
#elif defined(OQMC_ARCH_SSE)
	            "SSE"
#elif defined(OQMC_ARCH_ARM)
	            "ARM"
#else
	            "scalar"
#endif
	);
	std::printf("  \"order\": [");
	for(std::size_t k = 0; k < n; ++k)
	{
		std::printf("%s", k ? ", " : "");
		jsonString(cases[k].name);
	}
	std::printf("],\n  \"cases\": [\n");
	for(std::size_t k = 0; k < n; ++k)
	{
		const Case& c = cases[k];
		std::printf("    {\"name\": ");
		jsonString(c.name);
		std::printf(", \"library\": \"%s\", \"sampler\": \"%s\", \"shape\": \"%s\", \"per_draw\": %d, "
		            "\"width\": %d, \"height\": %d, \"spp\": %d, \"dims\": %d, \"values\": %.0f, "
		            "\"checksum\": %u, \"setup_ns\": %.0f, \"table_bytes\": %.0f, \"params\": ",
		            c.library.c_str(), c.sampler.c_str(), c.shape.c_str(), c.perDraw, c.image.width,
		            c.image.height, c.image.spp, c.image.dims, c.image.values(), c.checksum, c.setupNs,
		            c.cacheBytes);
		jsonString(c.params);
		std::printf(", \"ns_per_value\": [");
		for(std::size_t r = 0; r < c.nsPerValue.size(); ++r)
			std::printf("%s%.4f", r ? ", " : "", c.nsPerValue[r]);
		std::printf("], \"wall_ns_per_value\": [");
		for(std::size_t r = 0; r < c.wallNsPerValue.size(); ++r)
			std::printf("%s%.4f", r ? ", " : "", c.wallNsPerValue[r]);
		std::printf("]}%s\n", k + 1 < n ? "," : "");
	}
	std::printf("  ]\n}\n");
	return 0;
#endif
}
