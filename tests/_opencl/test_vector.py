"""The OpenCL vector path (pyoa._opencl.vector, kernels/vector.cl): which
requests take it, and that it, the table path and the direct path give the
NumPy backend's float32 bits exactly, for every orthogonal-array construction
and offset.

Each path is forced with ``OpenCLBackend(path=...)``: one backend per path and
module (the vector path builds one program per request *shape*, about a second
each the first time, so the cases below share a small set of shapes)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pyoa import reference as ref
from pyoa.reference import hashes as ref_hashes
from pyoa.catalogue.request import MAX_ARRAY_CELLS
from tests.helpers import U32_MAX, assert_same_bits, make

pytestmark = pytest.mark.opencl

PATHS = ("vector", "tables", "direct")
OFFSETS = ("cmj", "centered", "mj", "j")
#: 1 (full jitter), 0 (the centre of each cell) and an amount with many
#: significant bits (an inexact product in jitter_value).
JITTERS = (1.0, 0.0, 12345677 * 2.0**-24)

#: id -> (sampler arguments, requested dims). Every case has at least 8
#: samples per pixel and at most MAX_DIMS requested dimensions spanning
#: several blocks (later blocks read their own rows, docs/spec.md section 6),
#: so with path="vector" every whole-pixel rectangle takes the vector path
#: (asserted in test_paths_match_numpy).
CASES = {
    # prime field, s = 11: stratum and 'cmj' sub-stratum tabled as 4-bit
    # fields; 121 = 15 blocks of 8 + a tail of 1; dims across blocks of 12
    "bose-s11": ({"name": "bose", "spp": 121, "dims": 41}, [0, 11, 12, 25, 3, 40, 7, 8]),
    # GF(8): field tables; 64 samples = whole blocks; 16 dims = MAX_DIMS, 2 blocks of 9
    "bose-gf8": ({"name": "bose", "spp": 64, "dims": 16}, None),
    # s = 17: neither permutation tabled, both walks take the most rounds allowed (16)
    "bose-s17": ({"name": "bose", "spp": 289, "dims": 40}, [0, 17, 18, 39, 5]),
    # strength 3, s = 5, M = 25: the 'cmj' sub-stratum permutation is walked (8 rounds)
    "bush-s5-t3": ({"name": "bush", "spp": 125, "strength": 3, "dims": 13}, None),
    # s = 3, t = 4, M = 27 (walked, 6 rounds); blocks of t = 4 dims
    "cmjnd-s3-t4": ({"name": "cmjnd", "spp": 81, "strength": 4, "dims": 9}, None),
    # GF(9), index 2: M = 18 (walked, 15 rounds); blocks of 19
    "ak-q9": ({"name": "addelman-kempthorne", "spp": 162, "dims": 40}, [0, 18, 19, 38, 39, 4]),
    # s = 8, index 2: M = 16, the largest tabled sub-stratum permutation; blocks of 17
    "bose-bush-s8": ({"name": "bose-bush", "spp": 128, "dims": 35}, [0, 16, 17, 34, 9, 33]),
    # more than 16 dimensions: groups of 8 (kernels/vector.cl, VGROUPED), here 4 of 8 and a
    # tail group of 5 over blocks 0-3 of 12, in an order that returns to block 0
    "bose-s11-grouped": ({"name": "bose", "spp": 121, "dims": 48}, [*range(20, 48), 0, 1, 2, 13, 5, 3, 30, 31, 47]),
    # a whole grouped request of a walked sub-stratum: groups of 8, 8 and a tail of 7, blocks 0-3 of 6
    "bush-s5-t3-23": ({"name": "bush", "spp": 125, "strength": 3, "dims": 23}, None),
    # no dimension of block 0 (every slot's rows from vector_rows), blocks 1, 3 and 2 out of order
    "bose-s11-later-only": ({"name": "bose", "spp": 121, "dims": 48}, [12, 40, 47, 13, 30, 24, 25]),
}
CASE_PIXELS = [0, 7, U32_MAX]


@pytest.fixture(scope="module")
def backends(opencl, opencl_device):
    """One OpenCL backend per forced path, on the device under test."""
    from pyoa._opencl.backend import OpenCLBackend

    out = {p: OpenCLBackend(opencl_device, path=p) for p in PATHS}
    assert {p: b.path for p, b in out.items()} == {p: p for p in PATHS}
    return out


def fill(be, req) -> np.ndarray:
    """``req`` computed by backend ``be`` through ``fill``, chunked as
    Sampler.generate chunks it (``be.rows_per_chunk``), shaped (pixels,
    samples, dims). The output starts as NaN, so a value no launch writes
    cannot pass for a sample."""
    out = np.full((req.n_rows, req.n_dims), np.nan, dtype=np.float32)
    step = be.rows_per_chunk(req.n_dims)
    for r0 in range(0, req.n_rows, step):
        r1 = min(r0 + step, req.n_rows)
        be.fill(req, r0, r1, out[r0:r1])
    return out.reshape(len(req.pixels), len(req.samples), req.n_dims)


def spy(monkeypatch, be) -> dict[str, list]:
    """Record the rectangles ``be`` sends to the vector and the table path
    (from now to the end of the test; a later spy replaces this one)."""
    launched = {"vector": [], "tables": []}
    for path, attr in (("vector", "_launch_vector"), ("tables", "_launch_tabled")):
        real = getattr(type(be), attr).__get__(be)  # the method itself, not an earlier spy

        def wrapper(req, rect, *args, _real=real, _rects=launched[path]):
            _rects.append(rect)
            return _real(req, rect, *args)

        monkeypatch.setattr(be, attr, wrapper)
    return launched


def compare(be, smp, pixels=None, samples=None, dims=None, what=""):
    """``be`` against the NumPy sampler ``smp`` on one request, bit for bit; the request."""
    req = smp._request(pixels, samples, dims)
    want = smp.generate(pixels=pixels, samples=samples, dims=dims)
    assert_same_bits(fill(be, req), want, what)
    return req


def whole_rect(req):
    (rect,) = req.rectangles(0, req.n_rows)
    assert rect.n_k == len(req.samples) and rect.n_pixels == len(req.pixels)
    return rect


# ----------------------------------------------------------------------------- 1. every path == NumPy

@pytest.mark.parametrize("offset", OFFSETS)
@pytest.mark.parametrize("case", list(CASES))
@pytest.mark.parametrize("path", PATHS)
def test_paths_match_numpy(monkeypatch, backends, path, case, offset):
    """Every construction and offset, at several jitter amounts, on each forced
    path: the NumPy backend's bits. The rectangles go where the path says:
    vector (all of them here), tables (where they pay off) or direct."""
    from pyoa._opencl import vector

    kw, dims = CASES[case]
    be = backends[path]
    for jitter in JITTERS:
        smp = make(**kw, seed=1234567, offset=offset, jitter=jitter, backend="numpy")
        launched = spy(monkeypatch, be)
        req = compare(be, smp, CASE_PIXELS, None, dims, f"{path} {case} {offset} jitter={jitter}")
        rects = req.rectangles(0, req.n_rows)
        if path == "vector":
            assert all(vector.shape(req, r) is not None for r in rects)
            assert launched == {"vector": rects, "tables": []}
        elif path == "tables":
            assert launched == {"vector": [], "tables": [r for r in rects if req.tables_pay_off(r)]}
        else:
            assert launched == {"vector": [], "tables": []}
    if path == "tables" and offset in ("cmj", "centered"):
        assert launched["tables"], "the table path was never taken"


# ----------------------------------------------------------------------------- 2. which requests take it

def shape_of(name, spp, dims, offset=None, pixels=(0, 1), samples=None, req_dims=None, **kw):
    from pyoa._opencl import vector

    smp = make(name, spp, dims, offset=offset, backend="numpy", **kw)
    req = smp._request(list(pixels), samples, req_dims)
    return vector.shape(req, whole_rect(req))


def test_vector_path_taken_where_expected():
    from pyoa._opencl import vector

    shp = shape_of("bose", 121, 10)
    assert shp is not None
    assert (shp.s, shp.M, shp.n_dims, shp.n_k, shp.block_dims, shp.offset) == (11, 11, 10, 121, 12, "cmj")
    assert shp.s_packed and shp.sub == 1 and shp.jkey_bose
    assert (shp.n_blocks, shp.n_k_padded) == (16, 128)

    # exactly 8 samples: taken; 7: not (as a sampler of 4, and as 7 positions of 121)
    assert shape_of("bose", 121, 10, samples=range(8)) is not None
    assert shape_of("bose", 121, 10, samples=range(7)) is None
    assert shape_of("bose", 4, 3) is None
    # MAX_DIMS dimensions: taken; one more: not
    assert shape_of("bose", 121, vector.MAX_DIMS + 5, req_dims=range(vector.MAX_DIMS)) is not None
    assert shape_of("bose", 121, vector.MAX_DIMS + 1) is None
    # whole rows up to MAX_WHOLE_ROWS dimensions, groups of 8 beyond; later blocks flagged
    assert "#define VGROUPED 0" in shape_of("bose", 121, vector.MAX_WHOLE_ROWS).header()
    assert "#define VGROUPED 1" in shape_of("bose", 121, vector.MAX_WHOLE_ROWS + 1).header()
    assert not shape_of("bose", 121, 12).later and shape_of("bose", 121, 13).later
    # later blocks read the array's row records, which must fit MAX_ARRAY_CELLS words: Bush s = 16,
    # t = 5 (N = 2^20, 17 columns of 20-bit cells, one per word) fits without a later block only
    bush = {"strength": 5, "pixels": (0,)}
    assert shape_of("bush", 16**5, 17, **bush) is not None
    assert shape_of("bush", 16**5, 18, **bush) is None
    assert 16**5 * 17 > MAX_ARRAY_CELLS
    # a comparison sampler never
    assert shape_of("sobol", 64, 4) is None
    assert shape_of("halton", 64, 4) is None

    # 'centered' needs no sub-stratum permutation; 'cmj' with M <= 16 is tabled,
    # larger M and 'mj'/'j' walk
    assert shape_of("bose", 121, 10, "centered").sub == 0
    assert shape_of("bose-bush", 128, 10, "cmj").sub == 1  # M = 16
    assert shape_of("addelman-kempthorne", 162, 10, "cmj").sub == 2  # M = 18
    assert shape_of("bose", 121, 10, "mj").sub == 2
    assert shape_of("bose", 121, 10, "j").sub == 2
    assert shape_of("cmjnd", 81, 4, "j", strength=4).jkey_bose is False


def test_comparison_sampler_not_on_the_oa_vector_path(monkeypatch, backends):
    """Sobol on the vector backend: no OA vector program (shape is None), the
    generic kernel instead, with NumPy's bits."""
    from pyoa._opencl import vector

    be = backends["vector"]
    smp = make("sobol", 64, 4, seed=5, backend="numpy")
    req = smp._request([0, U32_MAX], None, None)
    assert vector.shape(req, whole_rect(req)) is None
    assert vector.baseline_shape(req, whole_rect(req)) is None
    launched = spy(monkeypatch, be)
    compare(be, smp, [0, U32_MAX], None, None, "sobol on the vector backend")
    assert launched == {"vector": [], "tables": []}


def test_vector_path_not_for_part_of_a_pixel():
    from pyoa._opencl import vector

    smp = make("bose", 121, 10, backend="numpy")
    req = smp._request([0, 1, 2], None, None)
    n = 121
    rects = req.rectangles(n // 2, 2 * n + 20)  # tail of pixel 0, pixel 1, head of pixel 2
    assert [(r.n_pixels, r.n_k) for r in rects] == [(1, n - n // 2), (1, n), (1, 20)]
    assert [vector.shape(req, r) is not None for r in rects] == [False, True, False]
    # 121 positions of which the first 120 only: still not whole pixels
    rect, = req.rectangles(0, n - 1)
    assert rect.n_k == n - 1 and vector.shape(req, rect) is None


def test_vector_path_round_limit():
    """A walk of more than MAX_ROUNDS rounds is not compiled: s = 17 (M = 17,
    mask 31, 16 rounds) is the largest taken; M = 81 or 34 (mask 127 or 63:
    48 or 31 rounds) is refused for every offset that walks it, but not for
    'centered' (no sub-stratum permutation); s = 37 (28 rounds) always."""
    from pyoa._opencl import vector

    assert vector.MAX_ROUNDS == 16
    assert (vector.walk_rounds(17), vector.walk_rounds(81), vector.walk_rounds(34), vector.walk_rounds(37)) == (
        16, 48, 31, 28)
    for offset in OFFSETS:
        shp = shape_of("bose", 289, 10, offset)
        assert shp is not None and not shp.s_packed and shp.sub == (0 if offset == "centered" else 2)
    for name, spp, kw in [("cmjnd", 243, {"strength": 5}),  # s = 3, M = 81
                          ("addelman-kempthorne", 578, {})]:  # s = 17, M = 34
        for offset in OFFSETS:
            shp = shape_of(name, spp, 6, offset, **kw)
            assert (shp is not None) == (offset == "centered"), (name, offset)
            if shp is not None:
                assert shp.sub == 0
    for offset in OFFSETS:
        assert shape_of("bose", 37 * 37, 10, offset) is None  # s = 37: the stratum walk is too long


permute_round = ref.hashes.permute_round  # one round of permute's cycle walk


def test_walk_rounds_bounds_every_walk():
    """For every start below l, the cycle walk of permute's round function ends
    (falls below l) within walk_rounds(l) rounds; brute force over small l and
    random seeds. The reference's round function is checked against
    pyoa.reference.permute itself (walk, then the final shift) and is a
    bijection of [0, w]."""
    from pyoa._numpy.hashes import permute_round as numpy_permute_round
    from pyoa._opencl import vector

    rng = np.random.default_rng(20240611)
    ls = list(range(1, 70)) + [127, 128, 129]
    seeds = [1, 2, 0x80000000, U32_MAX] + [int(v) for v in rng.integers(1, 2**32, 16)]
    tight = 0
    for l in ls:
        w = vector.walk_mask(l)
        assert w == (1 << max(l - 1, 0).bit_length()) - 1 and w >= l - 1 and (w + 1) & w == 0
        assert vector.walk_rounds(l) == w + 2 - l
        for p in seeds:
            rnd = [permute_round(x, p, w) for x in range(w + 1)]
            assert sorted(rnd) == list(range(w + 1)), f"round is not a bijection of [0, {w}] (l={l}, p={p})"
            assert rnd == [int(v) for v in numpy_permute_round(np.arange(w + 1, dtype=np.uint32), np.uint32(p), np.uint32(w))]
            longest = 0
            for i in range(l):
                x, rounds = rnd[i], 1
                while x >= l:
                    x, rounds = rnd[x], rounds + 1
                assert (x + p % l) % l == ref.permute(i, l, p), (i, l, p)
                longest = max(longest, rounds)
            assert longest <= vector.walk_rounds(l), f"l={l} p={p:#x}: a walk of {longest} rounds"
            tight += longest == vector.walk_rounds(l)
    assert tight > 0  # the bound is reached, so a smaller one would be wrong


# ----------------------------------------------------------------------------- 3. edge cases on the vector path

def vector_compare(monkeypatch, be, smp, pixels=None, samples=None, dims=None, what=""):
    """compare() on the vector backend, asserting every rectangle took the vector path."""
    launched = spy(monkeypatch, be)
    req = compare(be, smp, pixels, samples, dims, what)
    assert launched == {"vector": req.rectangles(0, req.n_rows), "tables": []}, what
    return req


@pytest.mark.parametrize("offset", OFFSETS)
def test_vector_edges_bose(monkeypatch, backends, offset):
    """Bose s = 11 (121 samples: a tail block of 1) with dims across blocks of
    12, pixels near 2^32, the largest seed, an unsorted subset of samples (9
    positions: a tail of 1 again; 16: whole blocks), and GF(8) (64 samples:
    no tail)."""
    be = backends["vector"]
    dims = CASES["bose-s11"][1]
    pixels = [U32_MAX, U32_MAX - 1, 0, 123456789, 2**31, U32_MAX - 7]
    for seed in (U32_MAX, 0):
        smp = make("bose", 121, 41, seed=seed, offset=offset, jitter=0.75, backend="numpy")
        vector_compare(monkeypatch, be, smp, pixels, None, dims, f"bose 121 seed={seed}")
        vector_compare(monkeypatch, be, smp, pixels, [0, 5, 7, 120, 3, 64, 99, 11, 42], dims, "9 samples")
        vector_compare(monkeypatch, be, smp, [U32_MAX, 5],
                       [120, 0, 5, 7, 3, 64, 99, 11, 42, 119, 1, 2, 60, 61, 8, 9], dims, "16 samples")
        # the same samples repeated: positions, not distinct indices
        vector_compare(monkeypatch, be, smp, [3], [7, 7, 0, 0, 120, 120, 5, 5, 9], dims, "repeated samples")
    smp = make("bose", 64, 16, seed=U32_MAX, offset=offset, jitter=0.5, backend="numpy")
    vector_compare(monkeypatch, be, smp, pixels, None, None, "GF(8), 64 samples")


def has_out_only_cycle(p: int, N: int) -> bool:
    """Whether Kensler's round with seed ``p`` on ``[0, walk_mask(N)]`` has a
    cycle of values ``>= N`` only: from any other value ``>= N`` at most
    ``walk_mask(N) + 1 - N`` rounds lead below ``N``."""
    w = ref_hashes.walk_mask(N)
    for y in range(N, w + 1):
        x = y
        for _ in range(w + 1 - N):
            x = ref_hashes.permute_round(x, p, w)
            if x < N:
                break
        else:
            return True
    return False


@pytest.mark.parametrize("spp", [121, 49, 169])
def test_vector_rows_walks_where_round_values_leave_the_range(monkeypatch, backends, spp):
    """vector_rows walks a later block's rows in one round and a lookup where
    at most 16 values of the walk's domain lie at or above N (N = 121: 7 of
    [0, 127]; N = 49: 15 of [0, 63]), and in a loop of rounds otherwise (N =
    169: 87 of [0, 255]). The lookup's results are walked once per seed from
    each of those values, and a value on a cycle of such values only
    (permute_round(y) = y, say) has no result: its walk is cut short, since no
    sample reaches it. Pixels whose block-1 or block-2 order seeds have such a
    cycle, and pixels whose seeds have none, give the NumPy bits."""
    be = backends["vector"]
    s = math.isqrt(spp)
    seed = 77
    smp = make("bose", spp, 3 * (s + 1), seed=seed, offset="cmj", backend="numpy")

    def cyclic(pixel):
        P = ref.pixel_seed(seed, pixel)
        orders = [ref_hashes.block_order_seed(ref.block_seed(P, b), b, spp) for b in (1, 2)]
        return any(has_out_only_cycle(r, spp) or has_out_only_cycle(ref.mix32(r), spp) for r in orders)

    found = [px for px in range(3000) if cyclic(px)][:4]
    assert len(found) == 4  # about 5 % of seeds (N = 121) have a fixed point past N
    pixels = found + [px for px in range(20) if px not in found][:4] + [U32_MAX]
    dims = [0, s, s + 1, 2 * s + 1, 2 * s + 2, 3 * s + 2]  # blocks 0, 1 and 2
    vector_compare(monkeypatch, be, smp, pixels, None, dims, f"bose {spp}, pixels {found}")


@pytest.mark.parametrize("name, spp, strength, offset, dims", [
    ("cmjnd", 3**10, 10, "centered", [0, 9, 10, 11, 34]),  # N = 59049, blocks of 10
    ("cmjnd", 6**6, 6, "centered", [0, 5, 6, 13, 20]),  # N = 46656, blocks of 6
])
def test_vector_rows_of_the_largest_arrays(monkeypatch, backends, name, spp, strength, offset, dims):
    """vector_rows walks in 16-bit lanes up to N = 65535 (vector.MAX_ROWS16).
    Its final shift, (x + p % N) mod N, would pass 65535 for N > 32768 if
    it added first (it did, and every later-block value of such arrays
    whose shift wrapped came out wrong); the largest sample indices and
    several seeds reach it."""
    from pyoa._opencl import vector

    be = backends["vector"]
    smp = make(name, spp, max(dims) + 1, strength=strength, seed=U32_MAX, offset=offset, backend="numpy")
    samples = [*range(spp - 40, spp), 0, 1, 32767, 32768]
    req = vector_compare(monkeypatch, be, smp, [0, 1, 2, 77, U32_MAX], samples, dims, f"{name} N={spp}")
    assert vector.shape(req, whole_rect(req)).later


@pytest.mark.parametrize("offset", ["cmj", "j"])
@pytest.mark.parametrize("spp", [64 * 64, 127 * 127])
def test_vector_path_long_sample_axis(monkeypatch, backends, spp, offset):
    """Many sample positions: s = 64 (GF(64), 512 blocks of 8) and s = 127
    (2017 blocks: longer than one work-group, so the values kernel is launched
    as groups of 64 plus a remainder at a global offset); neither permutation
    is tabled (walks of 1 and 2 rounds)."""
    from pyoa._opencl import vector

    be = backends["vector"]
    s = math.isqrt(spp)
    smp = make("bose", spp, 2 * s + 2, seed=2024, offset=offset, jitter=0.9, backend="numpy")
    req = vector_compare(monkeypatch, be, smp, [U32_MAX, 3], None, [0, s, s + 1, 2 * s + 1], f"bose s={s}")
    shp = vector.shape(req, whole_rect(req))
    assert not shp.s_packed and shp.sub == 2
    if s == 127:
        assert shp.n_blocks > be._axis_limit and shp.n_blocks % 64


@pytest.mark.parametrize("offset", ["cmj", "mj"])
def test_vector_path_in_chunks(monkeypatch, opencl_device, offset):
    """A request split into chunks whose boundaries fall inside pixels (a
    private backend with a small max_chunk_values): whole pixels take the
    vector path, the partial pixels the table or direct path, and the whole
    is NumPy's, bit for bit."""
    from pyoa._opencl import vector
    from pyoa._opencl.backend import OpenCLBackend

    be = OpenCLBackend(opencl_device, path="vector")
    kw, dims = CASES["bose-s11"]
    n, nd = kw["spp"], len(dims)
    smp = make(**kw, seed=99, offset=offset, jitter=0.3, backend="numpy")
    pixels = [U32_MAX, 0, 1, 2**31, 77, 5, 6, U32_MAX - 1]
    be.max_chunk_values = nd * (2 * n + n // 2 + 3)  # chunks of 2.5 pixels and 3 rows
    assert be.rows_per_chunk(nd) == 2 * n + n // 2 + 3
    launched = spy(monkeypatch, be)
    req = compare(be, smp, pixels, None, dims, f"chunks {offset}")
    assert launched["vector"], "no rectangle took the vector path"
    assert all(r.n_k == n and r.k0 == 0 for r in launched["vector"])
    step = be.rows_per_chunk(nd)
    rects = [r for r0 in range(0, req.n_rows, step) for r in req.rectangles(r0, min(r0 + step, req.n_rows))]
    partial = [r for r in rects if r.n_k < n]
    assert partial and all(vector.shape(req, r) is None for r in partial)
    assert launched["vector"] == [r for r in rects if r.n_k == n]
    assert launched["tables"] == [r for r in partial if req.tables_pay_off(r)]
    if offset == "cmj":
        assert launched["tables"]  # some partial rectangles tabled, ...
    assert len(launched["tables"]) < len(partial)  # ... and some direct
    assert any(r.n_pixels > 1 for r in launched["vector"])


# ----------------------------------------------------------------------------- 4. choosing the path

def test_bogus_path_is_refused(monkeypatch):
    from pyoa._opencl.backend import ENV_PATH, OpenCLBackend
    from pyoa._opencl.backend import PATHS as BACKEND_PATHS

    assert BACKEND_PATHS == ("auto", *PATHS)
    with pytest.raises(ValueError) as exc:
        OpenCLBackend(path="bogus")
    assert "bogus" in str(exc.value) and all(p in str(exc.value) for p in BACKEND_PATHS)
    monkeypatch.setenv(ENV_PATH, "bogus")
    with pytest.raises(ValueError) as exc:
        OpenCLBackend()
    assert "bogus" in str(exc.value) and ENV_PATH in str(exc.value)


def test_path_from_environment_and_auto(monkeypatch, opencl, opencl_device):
    from pyoa._opencl.backend import ENV_PATH, OpenCLBackend

    auto = "vector" if opencl.info.kind == "cpu" else "direct"
    monkeypatch.delenv(ENV_PATH, raising=False)
    assert OpenCLBackend(opencl_device).path == auto
    assert OpenCLBackend(opencl_device, path="auto").path == auto
    for p in PATHS:
        monkeypatch.setenv(ENV_PATH, p)
        assert OpenCLBackend(opencl_device).path == p
        other = "direct" if p != "direct" else "tables"
        assert OpenCLBackend(opencl_device, path=other).path == other  # the argument wins
    monkeypatch.setenv(ENV_PATH, "auto")
    assert OpenCLBackend(opencl_device).path == auto
    if opencl.info.kind == "cpu":
        assert auto == "vector"


# ----------------------------------------------------------------------------- 5. the padded 2D samplers

#: (name, spp, sampler dims, requested dims): 11 x 11 and the non-square 10 x
#: 12 grid; odd sampler dims give jittered2d its lone last dimension (N cells).
BASELINE_CASES = [
    ("jittered2d", 121, 10, None),
    ("jittered2d", 121, 9, [8, 0, 1, 7, 3]),
    ("cmj2d", 121, 10, None),
    ("cmj2d", 120, 7, [6, 5, 0, 1, 2]),
    ("jittered2d", 64, 16, None),
]


@pytest.mark.parametrize("jitter", JITTERS)
@pytest.mark.parametrize("case", BASELINE_CASES, ids=lambda c: f"{c[0]}-{c[1]}x{c[2]}")
@pytest.mark.parametrize("path", ["vector", "direct"])
def test_padded_2d_paths_match_numpy(monkeypatch, backends, path, case, jitter):
    """jittered2d and cmj2d: the vector kernel (vector_baseline) and the
    generic one give NumPy's bits, at pixels up to 2**32 - 1 and the largest seed."""
    from pyoa._opencl import vector

    name, spp, dims, req_dims = case
    be = backends[path]
    smp = make(name, spp, dims, seed=U32_MAX, backend="numpy", jitter=jitter)
    req = smp._request(CASE_PIXELS, None, req_dims)
    assert vector.baseline_shape(req, whole_rect(req)) is not None
    calls = []
    real = type(be)._launch_vector_baseline.__get__(be)
    monkeypatch.setattr(be, "_launch_vector_baseline", lambda *a: (calls.append(a[1]), real(*a)))
    compare(be, smp, CASE_PIXELS, None, req_dims, f"{name} {spp} dims {req_dims} on {path}")
    assert calls == (req.rectangles(0, req.n_rows) if path == "vector" else [])


def test_padded_2d_vector_shape_limits():
    """baseline_shape refuses fewer than 8 samples, more than MAX_DIMS
    dimensions and walks over MAX_ROUNDS (17 x 17 = 289 in [0, 511])."""
    from pyoa._opencl import vector

    def shp(name, spp, dims, samples=None):
        req = make(name, spp, dims, backend="numpy")._request([0, 1], samples, None)
        return vector.baseline_shape(req, req.rectangles(0, req.n_rows)[0])

    got = shp("cmj2d", 120, 4)
    assert (got.kind, got.a, got.b, got.N) == (2, 10, 12, 120)
    assert shp("jittered2d", 121, 3).N == 121
    assert shp("cmj2d", 121, 4, samples=list(range(7))) is None
    assert shp("cmj2d", 121, vector.MAX_DIMS + 1) is None
    assert vector.walk_rounds(289) > vector.MAX_ROUNDS and shp("jittered2d", 289, 4) is None


def test_auto_takes_the_vector_path_only_for_large_requests(monkeypatch, opencl, opencl_device):
    """``auto`` on a CPU builds a vector program only once VECTOR_MIN_VALUES
    values of its shape were asked for (a build costs about a second once),
    in one request or summed over several (a render's batches); a forced
    ``vector`` takes any size. All give NumPy's bits."""
    from pyoa._opencl import backend as backend_mod
    from pyoa._opencl.backend import OpenCLBackend

    if opencl.info.kind != "cpu":
        pytest.skip("auto picks the direct path on this device")
    monkeypatch.delenv(backend_mod.ENV_PATH, raising=False)
    auto, forced = OpenCLBackend(opencl_device), OpenCLBackend(opencl_device, path="vector")
    assert not auto.path_forced and forced.path_forced
    smp = make("bose", 121, 10, seed=9, backend="numpy")
    pixels = list(range(7))  # 8,470 values
    for be, takes in ((auto, False), (forced, True)):
        launched = spy(monkeypatch, be)
        req = compare(be, smp, pixels, None, None, f"small request, path_forced={be.path_forced}")
        assert bool(launched["vector"]) is takes
    # no shape built yet in this process (earlier tests share the context):
    # the third request of a shape reaches the threshold, and it and every
    # later one take the vector path
    from pyoa._opencl import vector

    monkeypatch.setattr(vector, "_programs", {})
    monkeypatch.setattr(backend_mod, "VECTOR_MIN_VALUES", 3 * len(pixels) * 121 * 9)
    smp9 = make("bose", 121, 9, seed=9, backend="numpy")
    for i, takes in enumerate((False, False, True, True)):
        launched = spy(monkeypatch, auto)
        req = compare(auto, smp9, [p + 7 * i for p in pixels], None, None, f"request {i} of the same shape")
        assert launched["vector"] == (req.rectangles(0, req.n_rows) if takes else []), i
    # one request at the threshold takes it at once
    monkeypatch.setattr(backend_mod, "VECTOR_MIN_VALUES", len(pixels) * 121 * 8)
    smp8 = make("bose", 121, 8, seed=9, backend="numpy")
    launched = spy(monkeypatch, auto)
    req = compare(auto, smp8, pixels, None, None, "request at the threshold")
    assert launched["vector"] == req.rectangles(0, req.n_rows)


def test_auto_prefers_the_table_path_over_walked_cmj(monkeypatch, opencl, opencl_device):
    """``auto``: 'cmj' with a walked permutation (Bush s = 5 t = 3, M = 25)
    takes the table path, which tables it; Bose s = 11 (both permutations as
    fields) takes the vector path; 'mj' always the vector path."""
    from pyoa._opencl import backend as backend_mod
    from pyoa._opencl.backend import OpenCLBackend

    if opencl.info.kind != "cpu":
        pytest.skip("auto picks the direct path on this device")
    monkeypatch.delenv(backend_mod.ENV_PATH, raising=False)
    monkeypatch.setattr(backend_mod, "VECTOR_MIN_VALUES", 0)
    be = OpenCLBackend(opencl_device)
    for kw, offset, where in [({"name": "bush", "spp": 125, "strength": 3}, "cmj", "tables"),
                              ({"name": "bush", "spp": 125, "strength": 3}, "mj", "vector"),
                              ({"name": "bose", "spp": 121}, "cmj", "vector")]:
        smp = make(**kw, dims=6, seed=2, offset=offset, backend="numpy")
        launched = spy(monkeypatch, be)
        req = compare(be, smp, [0, 3, U32_MAX], None, None, f"auto {kw} {offset}")
        assert launched[where] == req.rectangles(0, req.n_rows), (kw, offset, launched)
