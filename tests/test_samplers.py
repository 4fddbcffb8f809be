"""The user-facing API (pyoa.samplers): shapes, defaults, attributes, order and
chunk independence, memory cap, thread safety, input validation."""

from __future__ import annotations

import math
import re
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import pyoa
import pyoa._numpy.backend as numpy_backend
from tests.helpers import U32_MAX, assert_same_bits, reference_block


@pytest.fixture(params=[pytest.param(("bose", 49, 11, None), id="bose"),
                        pytest.param(("cmjnd", 64, 7, 3), id="cmjnd"),
                        pytest.param(("bush", 64, 11, 3), id="bush"),
                        pytest.param(("bose", 64, 11, None), id="bose-gf8"),
                        pytest.param(("addelman-kempthorne", 50, 13, None), id="ak-q5"),
                        pytest.param(("bose-bush", 32, 11, None), id="bb-s4")])
def smp(request, backend):
    name, spp, dims, strength = request.param
    return pyoa.sampler(name, spp=spp, dims=dims, strength=strength, seed=123, backend=backend)


# ----------------------------------------------------------------------------- shape, dtype, defaults

def test_shape_dtype_contiguity(smp):
    for kw, shape in [
        ({}, (1, smp.spp, smp.dims)),
        ({"pixels": range(3)}, (3, smp.spp, smp.dims)),
        ({"pixels": [7], "samples": [5, 2], "dims": [0]}, (1, 2, 1)),
        ({"samples": range(smp.spp - 1, -1, -1), "dims": [smp.dims - 1, 0]}, (1, smp.spp, 2)),
        ({"pixels": []}, (0, smp.spp, smp.dims)),
        ({"dims": []}, (1, smp.spp, 0)),
        ({"samples": range(0)}, (1, 0, smp.dims)),
    ]:
        x = smp.generate(**kw)
        assert x.shape == shape, kw
        assert x.dtype == np.float32
        assert x.flags["C_CONTIGUOUS"]
        assert np.all((x >= 0) & (x < 1))


def test_out_array_is_filled_and_returned(smp):
    """generate(out=...) writes the same bits into the caller's array and returns it;
    reusing one array gives each call's own values (nothing left from the last)."""
    want = smp.generate(pixels=[3, 4], samples=range(5), dims=[0, 2])
    out = np.full((2, 5, 2), np.nan, dtype=np.float32)
    assert smp.generate(pixels=[3, 4], samples=range(5), dims=[0, 2], out=out) is out
    assert_same_bits(out, want)
    other = smp.generate(pixels=[9, 10], samples=range(5), dims=[0, 2])
    assert smp.generate(pixels=[9, 10], samples=range(5), dims=[0, 2], out=out) is out
    assert_same_bits(out, other)
    whole = np.empty((3, smp.spp, smp.dims), np.float32)
    assert_same_bits(smp.generate(pixels=range(3), out=whole), smp.generate(pixels=range(3)))


@pytest.mark.parametrize("bad, exc, words", [
    (np.empty((2, 5, 2)), TypeError, "float32"),
    (np.empty((2, 5, 3), np.float32), ValueError, "(2, 5, 2)"),
    (np.empty((2, 2, 5), np.float32).transpose(0, 2, 1), TypeError, "C-contiguous"),
    (np.empty((2, 5, 2), np.float32)[::1].view(), None, None),  # a plain view is fine
    ([[0.0]], TypeError, "numpy.ndarray"),
])
def test_out_array_errors(bad, exc, words):
    smp = pyoa.sampler("bose", spp=49, dims=3, backend="numpy")
    if exc is None:
        smp.generate(pixels=[0, 1], samples=range(5), dims=[0, 2], out=bad)
        return
    with pytest.raises(exc, match=re.escape(words)):
        smp.generate(pixels=[0, 1], samples=range(5), dims=[0, 2], out=bad)
    frozen = np.empty((2, 5, 2), np.float32)
    frozen.flags.writeable = False
    with pytest.raises(TypeError, match="writeable"):
        smp.generate(pixels=[0, 1], samples=range(5), dims=[0, 2], out=frozen)


def test_defaults_are_pixel_0_all_samples_all_dims(smp):
    x = smp.generate()
    y = smp.generate(pixels=[0], samples=range(smp.spp), dims=range(smp.dims))
    assert_same_bits(x, y)
    assert_same_bits(x[:, :5, :], reference_block(smp, [0], range(5), range(smp.dims)))


def test_sampler_defaults():
    s = pyoa.sampler("bose", spp=9, dims=2, backend="numpy")
    assert (s.seed, s.offset, s.jitter) == (0, "cmj", 1.0)
    assert s.max_bytes > 0


def test_attributes_and_repr(backend):
    s = pyoa.sampler("bose", spp=121, dims=30, seed=42, offset="mj", jitter=0.1, backend=backend)
    assert (s.name, s.spp, s.dims, s.s, s.strength, s.block_dims) == ("bose", 121, 30, 11, 2, 12)
    assert (s.offset, s.seed, s.backend) == ("mj", 42, backend)
    assert s.jitter == float(np.float32(0.1)) and s.jitter != 0.1  # stored as float32
    assert isinstance(s.device, str) and s.device
    r = repr(s)
    for part in ("'bose'", "spp=121", "dims=30", "seed=42", "offset='mj'", "jitter=0.1", "s=11", "strength=2",
                 "block_dims=12", f"backend='{backend}'"):
        assert part in r, (part, r)
    c = pyoa.sampler("CMJND", spp=625, dims=4, backend=backend)
    assert (c.name, c.s, c.strength, c.block_dims) == ("cmjnd", 5, 4, 4)


@pytest.mark.parametrize("spp, dims, strength, want", [
    (64, 8, None, (2, 6)),   # largest t <= dims with spp = s^t
    (64, 3, None, (4, 3)),
    (64, 2, None, (8, 2)),
    (64, 1, None, (64, 1)),  # dims == 1: t = 1
    (64, 8, 2, (8, 2)),
    (64, 2, 3, (4, 3)),      # explicit strength may exceed dims
    (27, 5, None, (3, 3)),
    (2**24, 24, None, (2, 24)),
])
def test_cmjnd_strength_choice(spp, dims, strength, want):
    s = pyoa.sampler("cmjnd", spp=spp, dims=dims, strength=strength, backend="numpy")
    assert (s.s, s.strength) == want
    assert s.block_dims == s.strength


@pytest.mark.parametrize("spp, dims, strength, want", [
    (64, 8, None, (4, 3)),    # the largest t <= dims with spp = s^t and s >= t
    (64, 2, None, (8, 2)),
    (64, 5, 2, (8, 2)),
    (16, 8, None, (4, 2)),    # 2^4: s = 2 < t = 4
    (81, 8, None, (9, 2)),    # 3^4: s = 3 < t = 4; 9 = 3^2 is a prime power
    (256, 8, None, (4, 4)),
    (27, 5, None, (3, 3)),
    (27, 2, 3, (3, 3)),       # explicit strength may exceed dims
    (9, 1, None, (3, 2)),
    (3125, 5, None, (5, 5)),
    (2**24, 30, None, (8, 8)),
    (2**24, 7, None, (16, 6)),
    (2**24, 5, None, (64, 4)),
    (2**24, 3, None, (256, 3)),
    (2**24, 8, 4, (64, 4)),
    (4093**2, 4, None, (4093, 2)),
    (256**2, 2, None, (256, 2)),
    (17**4, 4, None, (17, 4)),  # 83521 = 289^2: strength 4 over GF(17), not GF(289)
])
def test_bush_strength_choice(spp, dims, strength, want):
    s = pyoa.sampler("bush", spp=spp, dims=dims, strength=strength, backend="numpy")
    assert (s.s, s.strength) == want
    assert s.block_dims == s.s + 1 and s.params.M == spp // s.s
    assert s.params.M == s.s ** (s.strength - 1)


def test_bush_attributes_and_repr(backend):
    s = pyoa.sampler("bush", spp=125, dims=20, seed=3, offset="mj", backend=backend)
    assert (s.name, s.spp, s.dims, s.s, s.strength, s.block_dims) == ("bush", 125, 20, 5, 3, 6)
    r = repr(s)
    for part in ("'bush'", "spp=125", "s=5", "strength=3", "block_dims=6"):
        assert part in r, (part, r)
    assert s.generate(pixels=[0, 1]).shape == (2, 125, 20)


@pytest.mark.parametrize("strength", [9, 12, 24])
def test_bush_impossible_strength_names_valid_counts(strength):
    """Bush needs s >= t and s^t <= 2^24, so strength 9..24 (accepted by the range
    check) has no valid count at all. The error must still be useful: name the
    nearest valid counts or say which strengths exist, not an empty "nearest: ;"."""
    with pytest.raises(ValueError) as info:
        pyoa.sampler("bush", spp=1000, dims=4, strength=strength, backend="numpy")
    msg = str(info.value)
    assert "nearest: ;" not in msg and not msg.rstrip().endswith("nearest:"), msg
    assert re.search(r"\d+ \(s=\d+", msg) or re.search(r"\b8\b", msg), msg


def test_valid_spp_bush_and_gf_bose():
    from pyoa.tables import gf

    bush = pyoa.valid_spp("bush")
    assert bush[:4] == [pyoa.SppChoice(4, 2, 2, 3), pyoa.SppChoice(9, 3, 2, 4), pyoa.SppChoice(16, 4, 2, 5),
                        pyoa.SppChoice(25, 5, 2, 6)]
    assert [c.spp for c in bush] == sorted(c.spp for c in bush)
    assert len(set(bush)) == len(bush)
    assert all(c.s**c.strength == c.spp and c.s >= c.strength and gf.is_supported(c.s) and c.block_dims == c.s + 1
               and c.spp <= 2**24 for c in bush)
    # independent enumeration
    want = sorted(pyoa.SppChoice(s**t, s, t, s + 1) for t in range(2, 25) for s in range(t, 4097)
                  if s**t <= 2**24 and gf.is_supported(s))
    assert bush == want
    assert {c.strength for c in bush} == set(range(2, 9))
    assert [c for c in bush if c.spp == 2**24] == [pyoa.SppChoice(2**24, s, t, s + 1)
                                                 for s, t in [(8, 8), (16, 6), (64, 4), (256, 3)]]
    assert [c.s for c in pyoa.valid_spp("bush", strength=5)] == [5, 7, 8, 9, 11, 13, 16, 17, 19, 23, 25, 27]
    assert pyoa.valid_spp("bush", strength=8) == [pyoa.SppChoice(2**24, 8, 8, 9)]
    # the neighbours on both sides of a count (one side past the smallest)
    assert [c.label() for c in pyoa.valid_spp("bush", near=8, strength=3)] == ["27 (s=3, t=3)"]
    assert [c.label() for c in pyoa.valid_spp("bush", near=100)] == ["81 (s=9)", "121 (s=11)"]
    bose = {c.s for c in pyoa.valid_spp("bose")}
    assert {4, 8, 9, 16, 25, 27, 32, 49, 64, 81, 121, 125, 128, 169, 243, 256} <= bose
    assert not bose & {6, 10, 12, 289, 343, 512, 625, 729, 1024, 2048, 4096}
    assert all(gf.is_supported(s) for s in bose)


@pytest.mark.parametrize("name, spp, dims, s", [("addelman-kempthorne", 18, 20, 3), ("addelman-kempthorne", 162, 3, 9),
                                                ("addelman-kempthorne", 2 * 2887**2, 1, 2887),
                                                ("addelman-kempthorne", 2 * 243**2, 500, 243),
                                                ("bose-bush", 8, 1, 2), ("bose-bush", 32, 20, 4),
                                                ("bose-bush", 32768, 2, 128)])
def test_index2_attributes_and_repr(backend, name, spp, dims, s):
    """N = 2s^2 means s strata per axis, strength 2, blocks of 2s+1 dimensions and
    M = 2s sub-strata, whatever dims is (no strength choice as for bush/cmjnd)."""
    smp = pyoa.sampler(name.upper() if s == 3 else name, spp=spp, dims=dims, seed=9, backend=backend)
    assert (smp.name, smp.spp, smp.dims, smp.s, smp.strength, smp.block_dims) == (name, spp, dims, s, 2, 2 * s + 1)
    assert smp.params.M == 2 * s and smp.params.M * smp.s == spp
    assert pyoa.sampler(name, spp=spp, dims=dims, strength=2, backend=backend).params == smp.params
    r = repr(smp)
    for part in (f"'{name}'", f"spp={spp}", f"s={s}", "strength=2", f"block_dims={2 * s + 1}"):
        assert part in r, (part, r)
    x = smp.generate(samples=[0, spp - 1], dims=[dims - 1])
    assert x.shape == (1, 2, 1) and x.dtype == np.float32 and np.all((x >= 0) & (x < 1))


def test_valid_spp_index2():
    """The catalogue against an independent enumeration: Addelman-Kempthorne q odd,
    a prime (up to 2887, the largest with 2q^2 <= 2^24) or a prime power <= 256;
    Bose-Bush s = 2..128, powers of two (GF(2s) tables up to 256)."""
    from tests.helpers import factor_prime_power, index2_levels

    ak = pyoa.valid_spp("addelman-kempthorne")
    want = [pyoa.SppChoice(2 * q * q, q, 2, 2 * q + 1) for q in index2_levels("addelman-kempthorne")]
    assert ak == want
    qs = [c.s for c in ak]
    assert qs[:9] == [3, 5, 7, 9, 11, 13, 17, 19, 23] and qs[-1] == 2887 and 2 * 2887**2 <= 2**24
    assert {9, 25, 27, 49, 81, 121, 125, 169, 243} <= set(qs)
    assert not set(qs) & {2, 4, 8, 15, 21, 256, 289, 343, 625, 729, 1331, 2187, 2197, 2401}
    assert all(factor_prime_power(q) and q % 2 for q in qs)
    assert 2 * 2897**2 > 2**24  # 2897 is the next prime: too many samples
    bb = pyoa.valid_spp("bose-bush")
    assert bb == [pyoa.SppChoice(2 * s * s, s, 2, 2 * s + 1) for s in (2, 4, 8, 16, 32, 64, 128)]
    assert [c.spp for c in bb] == [8, 32, 128, 512, 2048, 8192, 32768]
    assert [c.label() for c in pyoa.valid_spp("bose-bush", near=100)] == ["32 (s=4)", "128 (s=8)"]
    assert [c.label() for c in pyoa.valid_spp("addelman-kempthorne", near=100)] == ["98 (s=7)", "162 (s=9)"]
    assert [c.spp for c in pyoa.valid_spp("addelman-kempthorne", near=162)] == [98, 162, 242]  # both sides
    for name in ("addelman-kempthorne", "bose-bush"):
        assert pyoa.valid_spp(name, strength=2) == pyoa.valid_spp(name)
        with pytest.raises(ValueError, match="strength 2 only"):  # as pyoa.sampler refuses it
            pyoa.valid_spp(name, strength=3)
        assert pyoa.valid_spp(name, dims=1) == pyoa.valid_spp(name)


def test_addelman_kempthorne_kernel_constants_layout():
    """What the kernels read for Addelman-Kempthorne: [kappa, b[0..q), k[0..q), c[0..q)]
    (pyoa/oa.h indexes ak[1 + m], ak[1 + q + m], ak[1 + 2q + m]); nothing for the others."""
    from pyoa import catalogue as constructions
    from pyoa.tables import gf

    for q in (3, 27, 243, 2887):
        c = constructions.get("addelman-kempthorne")
        prm = c.resolve(2 * q * q, None, None)
        kappa, b, k, cc = gf.ak_constants(q)
        consts = c.constants(prm)
        assert consts == [kappa, *b, *k, *cc] and len(consts) == 1 + 3 * q
        assert all(0 <= v < q for v in consts)
        assert c.field_order(prm) == q and c.shape_args(prm) == (q,)
    bb = constructions.get("bose-bush")
    prm = bb.resolve(32, None, None)
    assert bb.constants(prm) == [] and bb.field_order(prm) == 8 and bb.shape_args(prm) == (4,)
    assert bb.function == "bose_bush" and constructions.get("addelman-kempthorne").function == "addelman_kempthorne"
    assert len({c.code for c in constructions.SAMPLERS.values()}) == len(constructions.SAMPLERS)


def test_samplers_listing():
    names = pyoa.samplers()
    from pyoa import catalogue

    # every registered sampler, OA constructions first, with its description
    assert list(names) == list(catalogue.SAMPLERS)
    for n, c in catalogue.SAMPLERS.items():  # its description, and the pbrt/Mitsuba names it answers to
        also = [f"{a} ({catalogue.ALIASES[a][1]})" for a in catalogue.aliases_of(n)]
        assert names[n] == c.description + (f"; also: {', '.join(also)}" if also else "")
    assert {"bose", "bush", "cmjnd", "random", "sobol"} <= set(names)
    assert all(isinstance(v, str) and v for v in names.values())


def test_valid_spp():
    bose = pyoa.valid_spp("bose")
    assert bose[0] == pyoa.SppChoice(4, 2, 2, 3)
    assert bose[-1] == pyoa.SppChoice(4093**2, 4093, 2, 4094)
    assert all(math.isqrt(c.spp) ** 2 == c.spp for c in bose)
    assert [c.spp for c in bose] == sorted(c.spp for c in bose)
    assert 120 not in [c.spp for c in bose] and 121 in [c.spp for c in bose]
    assert [c.label() for c in pyoa.valid_spp("bose", near=128)] == ["121 (s=11)", "169 (s=13)"]
    # prime powers count: 81 = 9^2 is nearer to 120 than 169
    assert [c.label() for c in pyoa.valid_spp("bose", near=120)] == ["81 (s=9)", "121 (s=11)"]
    # a valid count is listed with its neighbours on both sides
    assert [c.spp for c in pyoa.valid_spp("bose", near=121)] == [81, 121, 169]
    cubes = pyoa.valid_spp("cmjnd", strength=3)
    assert [c.spp for c in cubes] == [s**3 for s in range(2, 257)]
    assert cubes[1].label() == "27 (s=3, t=3)"
    two = pyoa.valid_spp("cmjnd", dims=2)
    assert {c.strength for c in two} == {2} and two[-1].spp == 4096**2
    with pytest.raises(ValueError, match="unknown sampler 'niederreiter'"):
        pyoa.valid_spp("niederreiter")


# ----------------------------------------------------------------------------- order and chunk independence

def test_order_independence(smp):
    pixels = [0, 5, 17, U32_MAX]
    whole = smp.generate(pixels=pixels)
    # split pixels
    assert_same_bits(np.concatenate([smp.generate(pixels=[p]) for p in pixels]), whole, "split pixels")
    # split samples
    cuts = [0, 1, smp.spp // 3, smp.spp - 1, smp.spp]
    parts = [smp.generate(pixels=pixels, samples=range(a, b)) for a, b in zip(cuts, cuts[1:])]
    assert_same_bits(np.concatenate(parts, axis=1), whole, "split samples")
    # permuted dims
    perm = np.random.default_rng(1).permutation(smp.dims)
    assert_same_bits(smp.generate(pixels=pixels, dims=perm.tolist()), whole[:, :, perm], "permuted dims")
    # reversed ranges
    rev = smp.generate(pixels=pixels[::-1], samples=range(smp.spp - 1, -1, -1), dims=range(smp.dims - 1, -1, -1))
    assert_same_bits(rev, whole[::-1, ::-1, ::-1], "reversed")
    # repeated indices and numpy index arrays of other integer dtypes
    rep = smp.generate(pixels=np.array([5, 5], dtype=np.int64), samples=np.array([3, 3, 0], dtype=np.uint16),
                       dims=np.array([1, 1], dtype=np.int8))
    assert_same_bits(rep, whole[[1, 1]][:, [3, 3, 0]][:, :, [1, 1]], "repeated")
    # one value at a time
    for a, b, c in [(0, 0, 0), (3, smp.spp - 1, smp.dims - 1), (1, 7, 3)]:
        one = smp.generate(pixels=[pixels[a]], samples=[b], dims=[c])
        assert_same_bits(one[0, 0, 0], whole[a, b, c], "single value")


@pytest.mark.parametrize("chunk", [1, 7, 64, 1000])
def test_chunking_does_not_change_results(monkeypatch, smp, chunk):
    pixels = range(U32_MAX - 4, U32_MAX + 1)
    want = smp.generate(pixels=pixels)
    if smp.backend == "numpy":
        monkeypatch.setattr(numpy_backend, "CHUNK_VALUES", chunk)
    else:
        monkeypatch.setattr(smp._backend, "max_chunk_values", chunk)
    n_rows = 5 * smp.spp
    assert smp._backend.rows_per_chunk(smp.dims) < n_rows  # really chunked
    calls = []
    fill = smp._backend.fill
    monkeypatch.setattr(smp._backend, "fill", lambda *a: (calls.append(a[1:3]), fill(*a))[1])
    got = smp.generate(pixels=pixels)
    assert_same_bits(got, want, f"chunk={chunk}")
    assert len(calls) > 1
    # chunks tile the rows exactly once (they may run in any order, on several threads)
    calls.sort()
    assert calls[0][0] == 0 and calls[-1][1] == n_rows
    assert all(a[1] == b[0] for a, b in zip(calls, calls[1:]))
    monkeypatch.setattr(smp._backend, "fill", fill)
    assert_same_bits(smp.generate(pixels=pixels, samples=[smp.spp - 1, 0], dims=[2, 0, 1]),
                     want[:, [smp.spp - 1, 0]][:, :, [2, 0, 1]])


def test_progress_bar_gives_same_result(monkeypatch, smp, capsys):
    want = smp.generate(pixels=range(3))
    if smp.backend == "numpy":
        monkeypatch.setattr(numpy_backend, "CHUNK_VALUES", 50)
    else:
        monkeypatch.setattr(smp._backend, "max_chunk_values", 50)
    assert_same_bits(smp.generate(pixels=range(3), progress=True), want)


# ----------------------------------------------------------------------------- memory cap

def test_max_bytes(backend):
    s = pyoa.sampler("bose", spp=121, dims=8, max_bytes=1000, backend=backend)
    with pytest.raises(ValueError) as exc:
        s.generate()
    msg = str(exc.value)
    assert "1 x 121 x 8" in msg
    assert "4.3 KiB" in msg  # 121 * 8 * 4 = 3872 bytes of values + 4 * (1 + 121 + 8) of indices
    assert "1000 B" in msg and "max_bytes" in msg
    # the cap is on the request, not the sampler: a smaller request fits
    assert s.generate(samples=range(26)).shape == (1, 26, 8)  # 832 + 4 * 35 = 972 bytes
    with pytest.raises(ValueError):
        s.generate(samples=range(27))  # 864 + 4 * 36 = 1008 bytes
    exact = pyoa.sampler("bose", spp=121, dims=8, max_bytes=121 * 8 * 4 + 4 * 130, backend=backend)
    assert exact.generate().shape == (1, 121, 8)
    with pytest.raises(ValueError):
        pyoa.sampler("bose", spp=121, dims=8, max_bytes=121 * 8 * 4 + 4 * 130 - 1, backend=backend).generate()


def test_max_bytes_large_request_message():
    s = pyoa.sampler("bose", spp=4093**2, dims=64, max_bytes="1G", backend="numpy")
    assert s.max_bytes == 1 << 30
    with pytest.raises(ValueError, match=re.escape("1000 x 16752649 x 64")) as exc:
        s.generate(pixels=range(1000))
    assert "TiB" in str(exc.value) and "1.0 GiB" in str(exc.value)


def test_max_bytes_from_environment(monkeypatch):
    monkeypatch.setenv("PYOA_MAX_BYTES", "2k")
    s = pyoa.sampler("bose", spp=121, dims=8, backend="numpy")
    assert s.max_bytes == 2048
    with pytest.raises(ValueError, match="PYOA_MAX_BYTES"):
        s.generate()


@pytest.mark.parametrize("text, want", [("4G", 4 << 30), ("512MiB", 512 << 20), ("1e9", 10**9), ("2k", 2048),
                                        ("100", 100)])
def test_parse_bytes(text, want):
    from pyoa.samplers import parse_bytes

    assert parse_bytes(text) == want


def test_parse_bytes_fraction_of_ram():
    from pyoa.samplers import _physical_memory, parse_bytes

    assert parse_bytes("0.25") == int(0.25 * _physical_memory())
    with pytest.raises(ValueError, match="memory size"):
        parse_bytes("lots")


# ----------------------------------------------------------------------------- threads

def test_thread_safety(smp):
    pixels = range(16)
    want = smp.generate(pixels=pixels)
    barrier = threading.Barrier(8)

    def work(k):
        barrier.wait()
        return [smp.generate(pixels=pixels) for _ in range(3)]

    with ThreadPoolExecutor(8) as pool:
        results = [x for xs in pool.map(work, range(8)) for x in xs]
    for x in results:
        assert_same_bits(x, want, "threaded")


def test_thread_safety_mixed_requests(backend):
    """Different requests interleaved on one sampler (and one shared backend)."""
    smp = pyoa.sampler("cmjnd", spp=81, dims=9, strength=4, seed=5, backend=backend)
    reqs = [dict(pixels=[k], samples=range(k % 81, 81), dims=range(k % 9, 9)) for k in range(24)]
    want = [smp.generate(**r) for r in reqs]
    with ThreadPoolExecutor(6) as pool:
        got = list(pool.map(lambda r: smp.generate(**r), reqs * 3))
    for g, w in zip(got, want * 3):
        assert_same_bits(g, w)


# ----------------------------------------------------------------------------- bad inputs

@pytest.mark.parametrize("kwargs, exc, words", [
    (dict(name="bose", spp=128), ValueError, ["128", "121 (s=11)", "169 (s=13)"]),
    (dict(name="bose", spp=100), ValueError, ["100", "prime", "81 (s=9)", "121 (s=11)", "valid for cmjnd (s=10)"]),
    (dict(name="bose", spp=4096**2), ValueError, ["prime", "4093"]),
    (dict(name="bose", spp=4099**2), ValueError, ["spp", "16777216"]),
    (dict(name="bose", spp=0), ValueError, ["spp"]),
    (dict(name="bose", spp=-4), ValueError, ["spp"]),
    (dict(name="bose", spp=121.0), TypeError, ["spp", "integer"]),
    (dict(name="bose", spp="121"), TypeError, ["spp"]),
    (dict(name="bose", spp=True), TypeError, ["spp"]),
    (dict(name="bose", spp=121, strength=3), ValueError, ["strength", "cmjnd", "bush"]),
    # Bose over GF(q): s must be a prime or a prime power <= 256
    (dict(name="bose", spp=36), ValueError, ["36", "prime power", "25 (s=5)", "49 (s=7)", "valid for", "cmjnd (s=6)"]),
    (dict(name="bose", spp=289**2), ValueError, ["83521", "256", "80089 (s=283)", "85849 (s=293)",
                                                 "valid for", "bush (s=17, t=4)",
                                                 "cmjnd (s=17, t=4)"]),
    (dict(name="bose", spp=512**2), ValueError, ["262144", "259081 (s=509)", "271441 (s=521)", "bush (s=64, t=3)"]),
    (dict(name="bose", spp=4096**2), ValueError, ["nearest: 16752649 (s=4093);", "bush (s=64, t=4)"]),
    # Bush: s a prime power, t <= s
    (dict(name="bush", spp=8, strength=3), ValueError, ["8", "s^3", "s >= t", "nearest: 27 (s=3, t=3);",
                                                        "valid for", "cmjnd (s=2, t=3)"]),
    (dict(name="bush", spp=16, strength=4), ValueError, ["16", "s^4", "nearest: 256 (s=4, t=4);",
                                                         "valid for", "bose (s=4)", "cmjnd (s=2, t=4)"]),
    (dict(name="bush", spp=36), ValueError, ["36", "prime power", "27 (s=3, t=3), 49 (s=7)", "cmjnd (s=6)"]),
    (dict(name="bush", spp=216, strength=3), ValueError, ["216", "125 (s=5, t=3)", "343 (s=7, t=3)",
                                                          "cmjnd (s=6, t=3)"]),
    (dict(name="bush", spp=289**2, strength=2), ValueError, ["83521", "s^2", "80089 (s=283)", "85849 (s=293)"]),
    (dict(name="bush", spp=1000, dims=3), ValueError, ["1000", "2 <= t <= 3", "961 (s=31)", "1024 (s=32)",
                                                       "cmjnd (s=10, t=3)"]),
    (dict(name="bush", spp=1), ValueError, ["nearest: 4 (s=2)"]),
    (dict(name="bush", spp=64, strength=1), ValueError, ["strength", "2"]),
    (dict(name="bush", spp=64, strength=25), ValueError, ["strength", "25"]),
    (dict(name="bush", spp=64, strength=0), ValueError, ["strength"]),
    (dict(name="bush", spp=64, strength=3.0), TypeError, ["strength"]),
    (dict(name="bush", spp=2**25), ValueError, ["spp", "16777216"]),
    (dict(name="bose", spp=121, strength=1), ValueError, ["strength 2"]),
    (dict(name="cmjnd", spp=1000, dims=2), ValueError, ["1000", "961 (s=31)", "1024 (s=32)"]),
    (dict(name="cmjnd", spp=100, dims=8, strength=3), ValueError, ["100", "s^3", "64 (s=4, t=3)", "125 (s=5, t=3)"]),
    (dict(name="cmjnd", spp=2**25, dims=25), ValueError, ["spp"]),
    (dict(name="cmjnd", spp=64, strength=0), ValueError, ["strength"]),
    (dict(name="cmjnd", spp=64, strength=25), ValueError, ["strength", "24"]),
    (dict(name="cmjnd", spp=64, strength=3.0), TypeError, ["strength"]),
    # Addelman-Kempthorne: q odd, a prime (<= 2887) or an odd prime power <= 256
    (dict(name="addelman-kempthorne", spp=32), ValueError, ["32", "odd", "18 (s=3)", "50 (s=5)",
                                                            "32 is valid for bose-bush (s=4)"]),
    (dict(name="addelman-kempthorne", spp=8), ValueError, ["8", "odd", "nearest: 18 (s=3);", "bose-bush (s=2)"]),
    (dict(name="addelman-kempthorne", spp=2 * 15**2), ValueError, ["450", "odd prime", "338 (s=13)", "578 (s=17)"]),
    (dict(name="addelman-kempthorne", spp=2 * 289**2), ValueError, ["167042", "prime power (<= 256)",
                                                                    "160178 (s=283)", "171698 (s=293)"]),
    (dict(name="addelman-kempthorne", spp=2 * 343**2), ValueError, ["235298", "227138 (s=337)", "240818 (s=347)"]),
    (dict(name="addelman-kempthorne", spp=2 * 2889**2), ValueError, ["16692642", "2887",
                                                                     "nearest: 16669538 (s=2887)"]),
    (dict(name="addelman-kempthorne", spp=2 * 2903**2), ValueError, ["spp", "16777216"]),
    (dict(name="addelman-kempthorne", spp=49), ValueError, ["49", "18 (s=3)", "50 (s=5)",
                                                            "valid for bose (s=7), bush (s=7), cmjnd (s=7)"]),
    (dict(name="addelman-kempthorne", spp=19), ValueError, ["19", "18 (s=3)", "50 (s=5)"]),
    (dict(name="addelman-kempthorne", spp=1), ValueError, ["18 (s=3)"]),
    (dict(name="addelman-kempthorne", spp=18, strength=3), ValueError, ["strength 2 only", "strength=3"]),
    (dict(name="addelman-kempthorne", spp=18, strength=1), ValueError, ["strength 2 only"]),
    (dict(name="addelman-kempthorne", spp=18, strength=2.0), TypeError, ["strength"]),
    # Bose-Bush: s a power of two up to 128
    (dict(name="bose-bush", spp=18), ValueError, ["18", "power of two", "8 (s=2)", "32 (s=4)",
                                                  "18 is valid for addelman-kempthorne (s=3)"]),
    (dict(name="bose-bush", spp=2 * 6**2), ValueError, ["72", "power of two", "32 (s=4)", "128 (s=8)"]),
    (dict(name="bose-bush", spp=2 * 256**2), ValueError, ["131072", "128", "nearest: 32768 (s=128)"]),
    (dict(name="bose-bush", spp=2 * 2887**2), ValueError, ["nearest: 32768 (s=128);",
                                                           "valid for addelman-kempthorne (s=2887)"]),
    (dict(name="bose-bush", spp=64), ValueError, ["64", "32 (s=4)", "bose (s=8)", "bush (s=4, t=3)"]),
    (dict(name="bose-bush", spp=2), ValueError, ["2", "nearest: 8 (s=2)"]),
    (dict(name="bose-bush", spp=33), ValueError, ["33", "32 (s=4)"]),
    (dict(name="bose-bush", spp=32, strength=3), ValueError, ["strength 2 only", "strength=3"]),
    (dict(name="bose-bush", spp=32, strength=4), ValueError, ["strength 2 only"]),
    (dict(name="bose-bush", spp=32, strength=0), ValueError, ["strength"]),
    (dict(name="bose", spp=121, dims=0), ValueError, ["dims"]),
    (dict(name="bose", spp=121, dims=-2), ValueError, ["dims"]),
    (dict(name="bose", spp=121, dims=2**20 + 1), ValueError, ["dims", "1048576"]),
    (dict(name="bose", spp=121, dims=2.0), TypeError, ["dims"]),
    (dict(name="bose", spp=121, dims="8"), TypeError, ["dims"]),
    (dict(name="bose", spp=121, dims=False), TypeError, ["dims"]),
    (dict(name="bose", spp=121, seed=-1), ValueError, ["seed"]),
    (dict(name="bose", spp=121, seed=2**32), ValueError, ["seed", "4294967295"]),
    (dict(name="bose", spp=121, seed=1.5), TypeError, ["seed"]),
    (dict(name="bose", spp=121, seed=True), TypeError, ["seed"]),
    (dict(name="bose", spp=121, seed="7"), TypeError, ["seed"]),
    (dict(name="bose", spp=121, offset="foo"), ValueError, ["offset", "'foo'", "cmj", "centered"]),
    (dict(name="bose", spp=121, offset=3), ValueError, ["offset"]),
    (dict(name="bose", spp=121, jitter=-0.1), ValueError, ["jitter", "[0, 1]"]),
    (dict(name="bose", spp=121, jitter=1.0000001), ValueError, ["jitter"]),
    (dict(name="bose", spp=121, jitter=float("nan")), ValueError, ["jitter", "nan"]),
    (dict(name="bose", spp=121, jitter=float("inf")), ValueError, ["jitter"]),
    (dict(name="bose", spp=121, jitter="0.5"), TypeError, ["jitter"]),
    (dict(name="bose", spp=121, jitter=None), TypeError, ["jitter"]),
    (dict(name="bose", spp=121, jitter=True), TypeError, ["jitter"]),
    (dict(name="niederreiter", spp=121), ValueError, ["niederreiter", "bose", "cmjnd", "sobol02"]),
    (dict(name=3, spp=121), TypeError, ["name"]),
    (dict(name="bose", spp=121, backend="cuda"), ValueError, ["cuda", "opencl", "numpy"]),
    (dict(name="bose", spp=121, backend=1), TypeError, ["backend"]),
    (dict(name="bose", spp=121, max_bytes=0), ValueError, ["max_bytes"]),
    (dict(name="bose", spp=121, max_bytes="lots"), ValueError, ["lots"]),
])
def test_bad_constructor_arguments(kwargs, exc, words):
    kwargs = {"dims": 4, **kwargs}
    name = kwargs.pop("name")
    with pytest.raises(exc) as info:
        pyoa.sampler(name, **kwargs)
    msg = str(info.value)
    for w in words:
        assert w in msg, f"{w!r} not in {msg!r}"


@pytest.mark.parametrize("kw", [dict(seed=np.uint32(U32_MAX)), dict(seed=np.int64(5)), dict(spp=np.int16(121)),
                                dict(jitter=np.float32(0.25)), dict(jitter=0), dict(jitter=1),
                                dict(strength=np.int8(2)), dict(max_bytes="1M"), dict(offset="centered")])
def test_good_unusual_constructor_arguments(kw):
    s = pyoa.sampler("bose", **{"spp": 121, "dims": 4, "backend": "numpy", **kw})
    assert s.generate(samples=[0]).shape == (1, 1, 4)
    assert type(s.seed) is int and type(s.spp) is int


BAD_INDICES = [
    (5, TypeError, ["range or a sequence"]),
    (np.int64(5), TypeError, ["range or a sequence"]),
    ("0", TypeError, []),
    (b"0", TypeError, []),
    ((i for i in range(2)), TypeError, []),
    ([1.0], TypeError, ["integers", "float"]),
    (np.array([0.0, 1.0]), TypeError, ["float"]),
    ([True, False], TypeError, ["bool"]),
    ([1, "a"], TypeError, []),
    (np.array([[0, 1]]), ValueError, ["one-dimensional", "(1, 2)"]),
    ([[0], [1]], ValueError, ["one-dimensional"]),
    (np.array(3), (ValueError, TypeError), []),
    ([-1], ValueError, ["-1"]),
    (np.array([0, -5]), ValueError, ["-5"]),
    (range(-1, 2), ValueError, []),
]


PIXEL_CASES = BAD_INDICES + [
    ([2**32], ValueError, ["4294967296"]),
    ([2**64], ValueError, []),
    (range(U32_MAX, U32_MAX + 2), ValueError, ["4294967296"]),
    (range(2**64), ValueError, ["pixels"]),
]


SAMPLE_CASES = BAD_INDICES + [
    ([9], ValueError, ["[0, 9)", "9"]),
    (range(0, 10), ValueError, ["[0, 9)"]),
    (np.arange(10), ValueError, ["[0, 9)"]),
]


DIM_CASES = BAD_INDICES + [
    ([2], ValueError, ["[0, 2)"]),
    (range(3), ValueError, ["[0, 2)"]),
]


BAD_INDEX_CASES = [
    (arg, *case) for arg, cases in (("pixels", PIXEL_CASES), ("samples", SAMPLE_CASES), ("dims", DIM_CASES))
    for case in cases
]


def _bad_index_id(case) -> str:
    # no memory address in an id (a generator's repr has one): pytest-xdist
    # workers must collect the same ids
    value = re.sub(r" at 0x[0-9a-f]+", "", repr(case[1]))
    return f"{case[0]}-{value:.40}".replace(" ", "")


@pytest.mark.parametrize("arg, value, exc, words", BAD_INDEX_CASES, ids=[_bad_index_id(c) for c in BAD_INDEX_CASES])
def test_bad_indices(arg, value, exc, words):
    s = pyoa.sampler("bose", spp=9, dims=2, backend="numpy")
    with pytest.raises(exc) as info:
        s.generate(**{arg: value})
    assert arg in str(info.value)
    for w in words:
        assert w in str(info.value)


def test_good_index_forms():
    s = pyoa.sampler("bose", spp=9, dims=3, seed=2, backend="numpy")
    want = s.generate(pixels=[1, U32_MAX], samples=[0, 8], dims=[2])
    for pixels in ([1, U32_MAX], (1, U32_MAX), np.array([1, U32_MAX], dtype=np.uint32),
                   np.array([1, U32_MAX], dtype=np.uint64), [np.int64(1), np.uint32(U32_MAX)],
                   np.array([1, U32_MAX], dtype=object)):
        assert_same_bits(s.generate(pixels=pixels, samples=range(0, 9, 8), dims=(2,)), want, repr(pixels))


@pytest.mark.parametrize("pixel, i, j, exc", [
    (-1, 0, 0, ValueError), (2**32, 0, 0, ValueError), (0, 9, 0, ValueError), (0, -1, 0, ValueError),
    (0, 0, 3, ValueError), (0.0, 0, 0, TypeError), (0, 1.0, 0, TypeError), (0, 0, True, TypeError),
])
def test_bad_value_arguments(pixel, i, j, exc):
    s = pyoa.sampler("bose", spp=9, dims=3, backend="numpy")
    with pytest.raises(exc):
        s.value(pixel, i, j)


def test_invalid_spp_error_is_fast():
    """cmjnd with dims=1 (t = 1: every spp >= 2 is valid) and spp=1: the error names
    the nearest counts; building it must not enumerate ~2^24 candidates."""
    import subprocess
    import sys

    code = "import pyoa\ntry:\n    pyoa.sampler('cmjnd', spp=1, dims=1)\nexcept ValueError as e:\n    print(e)\n"
    try:
        res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=5)
    except subprocess.TimeoutExpired:
        pytest.fail("pyoa.sampler('cmjnd', spp=1, dims=1) took more than 5 s to raise its ValueError")
    assert "2 (s=2, t=1)" in res.stdout, res.stdout + res.stderr
