"""pyoa/counts.h, the catalogue's sample counts in C, against the Python API.

The header's functions, built into a shared library as C99 and as C++14
(warnings as errors), must accept exactly the requests :class:`pyoa.Sampler`
accepts, resolve them to the same parameters (:mod:`pyoa.catalogue.params`, ``shape_args``)
and refuse the others with the same error kind and the same message (the
nearest valid counts, the samplers that accept the count). The Python side
is the oracle throughout: :func:`expect` runs the steps of
``Sampler.__init__`` on the catalogue's own functions, and
``test_resolve_matches_the_sampler`` checks it, and the C, against
``pyoa.Sampler`` itself.

Every sampler at every count 0..5000 and the edges (2^24, 2^24 + 1,
2^32 - 1); hypothesis draws up to 2^24 with strengths, dims, bases and
resolutions valid and invalid; every name and alias; the offsets; the
message buffer's truncation; the exact integer root that replaces Python's
float one at every rounding boundary. Set ``PYOA_REQUIRE_C=1`` to fail
instead of skip without gcc/g++.
"""

from __future__ import annotations

import ctypes
import functools
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import pyoa
from pyoa import catalogue
from pyoa.samplers import _offset
from pyoa.catalogue.entries import MAX_DIMS, MAX_SPP, REGISTRY, _labels, check_int
from pyoa.catalogue.params import OAParams, PointSetParams
from pyoa.catalogue.faure import BASES, zfaure_counts
from pyoa.reference.zfaure import grid_digits

from .test_c_headers import INCLUDE, WARN, compile_, need

SHIM = Path(__file__).parent / "c" / "counts_shim.c"

BUILDS = {
    "c99-O2": ("gcc", ".c", ["-std=c99", "-O2", *WARN]),
    "c++14-O2": ("g++", ".cpp", ["-std=c++14", "-O2", *WARN]),
}
OK, NAME, SPP, STRENGTH, OFFSET, RESOLUTION, DIMS, BASE = range(8)
FIELDS = 12  # pyoa_params' 9 fields, then the shape arguments a, b, c
STRIDE = 1024
U32 = 2**32 - 1
NAMES = list(catalogue.SAMPLERS)
MARK = 0xDEADBEEF
#: the image a zsobol case gets when a test does not vary it
HD = (1920, 1080)


@pytest.fixture(scope="module", params=list(BUILDS))
def lib(request, tmp_path_factory):
    compiler, suffix, flags = BUILDS[request.param]
    need(compiler, "PYOA_REQUIRE_C")
    d = tmp_path_factory.mktemp(request.param)
    src = d / f"counts_shim{suffix}"
    src.write_text(SHIM.read_text())
    so = d / "counts_shim.so"
    compile_(compiler, [*flags, "-shared", "-fPIC", f"-I{INCLUDE}", str(src), "-o", str(so)], d)
    lib = ctypes.CDLL(str(so))
    lib.t_sampler_name.restype = ctypes.c_char_p
    lib.t_name_error.restype = ctypes.c_size_t
    lib.t_nearest_max.restype = ctypes.c_size_t
    return lib


# ----------------------------------------------------------------------------- the oracle

@pytest.fixture(scope="module", autouse=True)
def quick_choices():
    """Construction.choices rebuilds its list (4096 tuples for jittered2d)
    on every call, and each refused count's message calls it: memoized here
    (the same lists, from the same code), so that thousands of messages take
    seconds. Restored after this module."""
    saved = {}
    for cls in {type(c) for c in REGISTRY.values()}:
        saved[cls] = cls.__dict__.get("choices")  # None: inherited
        cls.choices = functools.lru_cache(maxsize=None)(cls.choices)
    yield
    for cls, own in saved.items():
        if own is None:
            del cls.choices
        else:
            cls.choices = own


def flat_params(construction, prm, dims) -> tuple:
    """``(s, strength, block_dims, M, dims)`` of C's pyoa_params for Python's
    parameters (pyoa.catalogue.params: one type per family), which C holds in one flat
    struct: the listing's s, strength and block_dims (``construction.choice``);
    M an OA's sub-strata, cmj2d's second side, jittered2d's 1 and every other
    sampler's count; dims 0 for an OA (none depends on it)."""
    shown = construction.choice(prm)
    if isinstance(prm, OAParams):
        M, dims = prm.M, None
    elif isinstance(prm, PointSetParams):
        M = 1 if construction.name == "jittered2d" else prm.c
    else:
        M = prm.N
    return (shown.s, shown.strength, shown.block_dims, M, dims or 0)


def params_row(construction, spp, dims, prm) -> tuple:
    """The C shim's row for Python's parameters: pyoa_params' fields, then the
    shape arguments as the kernel's three words a, b, c (zero-padded; those of
    the entry's launch where it has more than three, zfaure's (N, b | k << 16,
    width))."""
    width, height = construction.arguments(prm).get("resolution") or (0, 0)
    shape = construction.shape_args(prm)
    if len(shape) > 3:
        shape = tuple(int(w) for w in construction.launch(prm, None, 1.0).args[:3])
    shape = (*shape, 0, 0, 0)[:3]
    return (construction.code, spp, *flat_params(construction, prm, dims), width, height, *shape)


@functools.lru_cache(maxsize=None)
def expect(name, spp, strength=None, dims=None, base=None, resolution=None, offset=None, check_offset=False):
    """What the Python API does with a request, in pyoa.Sampler.__init__'s
    order: ``(OK, params_row)`` or ``(error code, message)``. ``dims=None``
    stands for C's 0 (unknown: valid_spp's dims=None, which the Sampler
    itself never has). A count outside [1, 2^24] gets the Sampler's message
    and then the nearest counts that C adds."""
    try:
        construction = catalogue.get(name)
    except ValueError as exc:
        return NAME, str(exc)
    try:
        check_int("spp", spp, 1, MAX_SPP)
    except ValueError as exc:
        msg = str(exc)
        try:
            if dims is None or dims <= MAX_DIMS:
                construction.solve(1, dims, strength)
                msg += f"; nearest: {_labels(construction.nearest(spp, dims, strength))}"
        except ValueError:
            pass
        return SPP, msg
    if dims is not None:
        try:
            check_int("dims", dims, 1, MAX_DIMS)
        except ValueError as exc:
            return DIMS, str(exc)
    if check_offset:
        try:
            _offset(construction, offset)
        except ValueError as exc:
            return OFFSET, str(exc)
    try:
        construction.solve(spp, dims, strength)
    except ValueError as exc:  # an OA raises for its strength only, a comparison sampler its strength first
        return (STRENGTH if strength is not None else DIMS), str(exc)
    try:
        prm = construction.resolve(spp, dims, strength)
    except ValueError as exc:
        return SPP, str(exc)
    try:
        prm = construction.with_resolution(prm, resolution)
    except ValueError as exc:
        return RESOLUTION, str(exc)
    try:
        prm = construction.with_base(prm, base)
    except ValueError as exc:
        return BASE, str(exc)
    return OK, params_row(construction, spp, dims, prm)


def c_solve(lib, cases):
    """t_solve over (name, spp, strength, dims, base, resolution) cases: [(code, row or message)]."""
    n = len(cases)
    cols = [np.zeros(n, np.uint32) for _ in range(7)]
    for k, (name, spp, strength, dims, base, resolution) in enumerate(cases):
        width, height = resolution or (0, 0)
        for col, v in zip(cols, (catalogue.get(name).code, spp, strength or 0, dims or 0, base or 0, width, height)):
            col[k] = v
    rc = np.zeros(n, np.int32)
    params = np.full((n, FIELDS), MARK, np.uint32)
    messages = ctypes.create_string_buffer(n * STRIDE)
    lib.t_solve(ctypes.c_size_t(n), *(c.ctypes.data_as(ctypes.c_void_p) for c in (*cols, rc, params)), messages,
                ctypes.c_size_t(STRIDE))
    raw = messages.raw
    out = []
    for k in range(n):
        if rc[k] == OK:
            out.append((OK, tuple(int(x) for x in params[k])))
        else:
            assert (params[k] == MARK).all(), "params written on error"
            out.append((int(rc[k]), raw[k * STRIDE:(k + 1) * STRIDE].split(b"\0", 1)[0].decode()))
    return out


def check(lib, cases):
    got = c_solve(lib, cases)
    for case, g in zip(cases, got):
        want = expect(*case)
        assert g == want, f"{case}: C {g} != Python {want}"
    return got


# ----------------------------------------------------------------------------- names

def test_every_name_and_alias(lib):
    typed = [*NAMES, *catalogue.ALIASES, *(n.upper() for n in NAMES), *(a.title() for a in catalogue.ALIASES),
             "Addelman-Kempthorne", "addelman-\u212aempthorne", "ADDELMAN-\u212aEMPTHORNE"]
    for name in typed:
        code = ctypes.c_uint32(MARK)
        assert lib.t_lookup(name.encode(), ctypes.byref(code)) == OK, name
        assert code.value == catalogue.get(name).code, name
    for code, name in enumerate(n for n in sorted(NAMES, key=lambda n: catalogue.get(n).code)):
        assert lib.t_sampler_name(code).decode() == name
        assert bool(lib.t_needs_resolution(code)) == catalogue.get(name).needs_resolution
    assert lib.t_sampler_name(len(NAMES)) is None


@pytest.mark.parametrize("name", ["bosee", "", "bose ", " bose", "it's", 'say "hi"', "both'\"", "tab\there", "b\\s",
                                  "\u00fcnknown", "bose-", "sobol\x01", "kelvin\u212a", "addelman-kempthornee"])
def test_unknown_names_are_refused_with_the_python_message(lib, name):
    with pytest.raises(ValueError) as info:
        catalogue.get(name)
    code = ctypes.c_uint32(MARK)
    assert lib.t_lookup(name.encode(), ctypes.byref(code)) == NAME
    assert code.value == MARK
    buf = ctypes.create_string_buffer(STRIDE)
    n = lib.t_name_error(name.encode(), buf, ctypes.c_size_t(STRIDE))
    assert buf.value.decode() == str(info.value)
    assert n == len(str(info.value).encode())
    params, offset = (ctypes.c_uint32 * FIELDS)(), ctypes.c_uint32()
    assert lib.t_resolve(name.encode(), 4, 0, 0, None, 0, 0, 0, params, ctypes.byref(offset), buf, STRIDE) == NAME
    assert buf.value.decode() == str(info.value)


# ----------------------------------------------------------------------------- counts

EDGES = [MAX_SPP - 1, MAX_SPP, MAX_SPP + 1, U32, 4093**2, 4093**2 + 1, 4096**2 - 1, 2 * 2887**2, 2 * 2887**2 + 2,
         2 * 128**2, 2**16, 2**16 + 1, 8**8, 16777213, 4093 * 4099]


@pytest.mark.parametrize("name", NAMES)
def test_every_count_to_5000_and_the_edges(lib, name):
    """Every spp in 0..5001 and the edges, strength and dims not given (and
    a second dims for the entries that read it): params, shape arguments,
    error kind and message equal Python's."""
    resolution = HD if catalogue.get(name).needs_resolution else None
    counts = [*range(0, 5002), *EDGES]
    cases = [(name, spp, None, None, None, resolution) for spp in counts]
    if name in ("bush", "cmjnd", "faure", "jittered2d"):  # the entries whose params read dims
        squares = {m * m + d for m in range(1, 80) for d in (-1, 0, 1)}
        every = 5 if name != "jittered2d" else MAX_SPP  # dims only changes jittered2d's valid (square) counts
        cases += [(name, spp, None, 3, None, resolution) for spp in counts if spp % every == 0 or spp in squares]
    got = check(lib, cases)
    valid = {case[1] for case, g in zip(cases, got) if g[0] == OK}
    # both outcomes are compared: some counts valid, some (at least 0 and 2^24 + 1) refused
    assert valid and len(valid) < len(counts), name


def valid_counts(name, **kw):
    return [c.spp for c in catalogue.valid_spp(name, **kw)] if catalogue.get(name).family == "oa" else []


def test_every_strength_of_bush_and_cmjnd_at_its_valid_counts(lib):
    """Each strength 1..26 (valid and not) at every valid count of each
    strength, its neighbours, and several dims."""
    cases = []
    for name, top in (("bush", 8), ("cmjnd", 24)):
        for t in range(2, top + 1):
            near = {n + d for n in valid_counts(name, strength=t) for d in (-1, 0, 1)}
            near = sorted(near)[:300] + sorted(near)[-30:]
            for strength in (None, t, t + 1, 1, 25, 26):
                for dims in (None, 1, 2, t, t + 3):
                    cases += [(name, spp, strength, dims, None, None) for spp in near[::7]]
    cases += [(name, spp, strength, None, None, None) for name in ("bose", "addelman-kempthorne", "bose-bush")
              for strength in (None, 1, 2, 3) for spp in valid_counts(name)[::5] + [10, 49, 50]]
    check(lib, cases)


# hypothesis: any sampler, counts anywhere up to 2^24 and past, strengths, dims, bases, resolutions

def _power(s, t, d):
    return max(0, min(s**t + d, U32))


spp_values = st.one_of(st.integers(0, 5001), st.integers(1, MAX_SPP), st.sampled_from(EDGES),
                       st.builds(_power, st.integers(2, 300), st.integers(2, 8), st.integers(-1, 1)),
                       st.builds(_power, st.just(2), st.integers(0, 24), st.integers(-1, 1)))
dims_values = st.one_of(st.none(), st.integers(1, 40), st.sampled_from([6542, 6543, 21201, 21202, MAX_DIMS, MAX_DIMS + 1,
                                                                        U32, 4093, 4094]))
strength_values = st.one_of(st.none(), st.none(), st.integers(1, 26), st.sampled_from([100, U32]))
base_values = st.one_of(st.none(), st.none(), st.integers(1, 4200), st.sampled_from([*BASES[:20], *BASES[-5:], U32]))
resolution_values = st.one_of(st.none(), st.just(HD), st.tuples(st.integers(0, 70000), st.integers(0, 70000)),
                              st.sampled_from([(1, 1), (65536, 65536), (65537, 1), (1, 65537), (0, 0), (0, 5), (7, 0)]))


@st.composite
def requests(draw):
    name = draw(st.sampled_from(NAMES))
    c = catalogue.get(name)
    resolution = draw(resolution_values) if c.needs_resolution or draw(st.integers(0, 9)) == 0 else None
    if resolution == (0, 0):
        resolution = None  # C's 0 x 0 is Python's None
    base = draw(base_values) if c.has_base or draw(st.integers(0, 9)) == 0 else None
    return (name, draw(spp_values), draw(strength_values), draw(dims_values), base, resolution)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.lists(requests(), min_size=1, max_size=60))
def test_random_requests_match_python(lib, cases):
    check(lib, cases)


def test_faure_bases(lib):
    """Every base 1..4100 and some beyond, at counts that put the base below,
    at and above the default's."""
    bases = [*range(1, 4101), 10**6, U32]
    cases = [("faure", 1, None, None, base, None) for base in bases]
    cases += [("faure", spp, None, dims, base, None) for base in bases[::7] + list(BASES[-3:])
              for spp, dims in ((1000, 5), (MAX_SPP, None), (3, 8))]
    got = check(lib, cases)
    assert sum(g[0] == OK for g in got[: len(bases)]) == len(BASES)


def test_zfaure_counts_bases_and_the_64_bit_index(lib):
    """zfaure's counts, the prime powers b^m (m >= 2, the count fixes b): every one with its neighbours
    (near 2^24 the nearest valid counts lie thousands away); a base given: the count's own, another
    prime's (the message lists its counts, "..." past six), non-primes; and the images around the
    64-bit limit b^(2k) N <= 2^64 of reference.zfaure.check_shape, where it binds: sides b^(k-1) and
    b^(k-1) + 1 of base 1621 at m = 2 (k = 2: 0.98 * 2^64 fits) and 1627 (past it), 137 and 139 at
    m = 3 (k = 3), 4093 at m = 2."""
    counts = list(zfaure_counts())
    cases = [("zfaure", n + d, None, None, None, HD) for n in counts for d in (-1, 0, 1)]
    cases += [("zfaure", n, None, None, base, HD) for n in (4, 8, 125, 4093**2, MAX_SPP)
              for base in (1, 2, 3, 4, 5, 4093, 4099, U32)]
    for b, m in ((1621, 2), (1627, 2), (137, 3), (139, 3), (4093, 2)):
        k = grid_digits(b, 65536, 1)
        for side in (b ** (k - 1), b ** (k - 1) + 1):
            for res in ((side, 1), (1, side), (side, side)):
                cases += [("zfaure", b**m, None, None, base, res) for base in (None, b)]
    got = check(lib, cases)
    kinds = {g[0] for g in got}
    assert {OK, SPP, RESOLUTION, BASE} <= kinds, kinds


def test_resolutions(lib):
    sizes = [None, (1, 1), (5, 3), HD, (65536, 65536), (65537, 1), (1, 65537), (0, 5), (7, 0), (U32, U32)]
    cases = [(name, spp, None, None, None, r) for name in NAMES for spp in (16, 17) for r in sizes]
    got = check(lib, cases)
    assert any(g[0] == RESOLUTION for g in got) and any(g[0] == OK and g[1][0] == 11 for g in got)


# ----------------------------------------------------------------------------- the whole Sampler

@st.composite
def sampler_requests(draw):
    name, spp, strength, dims, base, resolution = draw(requests())
    offset = draw(st.one_of(st.none(), st.none(), st.sampled_from(["cmj", "mj", "j", "centered", "CMJ", "x", "it's", ""])))
    typed = draw(st.sampled_from([name, name.upper(), *catalogue.aliases_of(name)]))
    dims = dims if dims is not None and dims <= U32 else draw(st.integers(1, 12))
    return typed, spp, strength, dims, base, resolution, offset


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.lists(sampler_requests(), min_size=1, max_size=8))
def test_resolve_matches_the_sampler(lib, cases):
    """pyoa_resolve against pyoa.Sampler itself (the NumPy backend): the same
    requests accepted, with the same s, strength, block_dims, base,
    resolution and offset, the others refused with the same message (and
    for a count outside [1, 2^24], the Sampler's message followed by the
    nearest counts). Also checks :func:`expect`, the oracle of the other
    tests, against the Sampler."""
    for typed, spp, strength, dims, base, resolution, offset in cases:
        params, code = (ctypes.c_uint32 * FIELDS)(*[MARK] * FIELDS), ctypes.c_uint32(MARK)
        buf = ctypes.create_string_buffer(STRIDE)
        width, height = resolution or (0, 0)
        rc = lib.t_resolve(typed.encode(), spp, strength or 0, dims, None if offset is None else offset.encode(),
                           base or 0, width, height, params, ctypes.byref(code), buf, STRIDE)
        want = expect(typed, spp, strength, dims, base, resolution, offset, True)
        try:
            smp = pyoa.Sampler(typed, spp=spp, dims=dims, strength=strength, offset=offset, resolution=resolution,
                               base=base, backend="numpy")
        except ValueError as exc:
            assert want[0] != OK and (want[1] == str(exc) or want[1].startswith(str(exc) + "; nearest: "))
            assert rc == want[0] and buf.value.decode() == want[1], (typed, spp, strength, dims, base, resolution, offset)
            assert list(params) == [MARK] * FIELDS and code.value == MARK
            continue
        assert want[0] == OK and rc == OK, (typed, spp, strength, dims, base, resolution, offset, buf.value)
        row = tuple(params)
        assert row == want[1]
        entry = catalogue.get(typed)
        assert row[:7] == (entry.code, smp.spp, smp.s, smp.strength, smp.block_dims,
                           *flat_params(entry, smp.params, smp.dims)[3:])
        assert (row[7], row[8]) == (smp.resolution or (0, 0))
        assert smp.base in (None, row[2])
        want_offset = 4 if smp.offset is None else ("centered", "j", "mj", "cmj").index(smp.offset)
        assert code.value == want_offset


# ----------------------------------------------------------------------------- offsets

OFFSET_TYPED = [None, "centered", "j", "mj", "cmj", "CMJ", "Cmj", "", " cmj", "x", "it's", "cm"]


@pytest.mark.parametrize("offset", OFFSET_TYPED)
def test_offsets(lib, offset):
    typed = None if offset is None else offset.encode()
    code = ctypes.c_uint32(MARK)
    known = lib.t_offset_code(typed, ctypes.byref(code))
    valid = ("centered", "j", "mj", "cmj")
    if offset is None or offset in valid:
        assert known == OK and code.value == valid.index(offset or "cmj")
    else:
        assert known == OFFSET and code.value == MARK
    for name in NAMES:
        construction = catalogue.get(name)
        code = ctypes.c_uint32(MARK)
        buf = ctypes.create_string_buffer(STRIDE)
        rc = lib.t_sampler_offset(construction.code, typed, ctypes.byref(code), buf, STRIDE)
        try:
            got = _offset(construction, offset)
        except ValueError as exc:
            assert (rc, buf.value.decode(), code.value) == (OFFSET, str(exc), MARK)
            continue
        assert rc == OK and code.value == (4 if got is None else valid.index(got))
    code = ctypes.c_uint32(MARK)
    assert lib.t_sampler_offset(len(NAMES), typed, ctypes.byref(code), None, 0) == NAME and code.value == MARK
    params = (ctypes.c_uint32 * FIELDS)()  # the offset's code may go nowhere
    assert lib.t_resolve(b"bose", 4, 0, 0, typed, 0, 0, 0, params, None, None, 0) == (OK if known == OK else OFFSET)


# ----------------------------------------------------------------------------- nearest

nearest_requests = st.tuples(st.sampled_from(NAMES), spp_values, st.one_of(st.none(), st.integers(1, 40)),
                             st.one_of(st.none(), st.none(), st.integers(1, 26)))


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.lists(nearest_requests, min_size=1, max_size=40))
def test_nearest_matches_valid_spp(lib, cases):
    """pyoa_nearest lists valid_spp(name, near=spp, dims, strength); where
    valid_spp raises (a strength or dims the sampler cannot have) it lists
    nothing. pyoa_nearest_spp is nearest_spp, 0 for none."""
    cases += [("bose", 0, None, None), ("cmjnd", 64, None, None), ("bush", 64, None, None), ("cmjnd", 2**24, 25, None),
              ("cmjnd", 2**24, None, None), ("pmj02", U32, None, None), ("faure", 0, 3, None), ("bose", 3, None, 3)]
    n = len(cases)
    top = lib.t_nearest_max()
    cols = [np.asarray([catalogue.get(c[0]).code for c in cases], np.uint32),
            *(np.asarray([c[k] or 0 for c in cases], np.uint32) for k in (1, 2, 3))]
    counts, out, best = np.zeros(n, np.uint32), np.zeros((n, top, FIELDS), np.uint32), np.zeros(n, np.uint32)
    lib.t_nearest(ctypes.c_size_t(n), *(c.ctypes.data_as(ctypes.c_void_p) for c in cols), ctypes.c_size_t(top),
                  *(a.ctypes.data_as(ctypes.c_void_p) for a in (counts, out, best)))
    for k, (name, spp, dims, strength) in enumerate(cases):
        try:
            want = list(catalogue.valid_spp(name, near=spp, dims=dims, strength=strength))
        except ValueError:
            assert counts[k] == 0 and best[k] == 0, cases[k]
            continue
        got = [tuple(int(x) for x in row[1:5]) for row in out[k, : counts[k]]]
        assert got == [(c.spp, c.s, c.strength, c.block_dims) for c in want], cases[k]
        assert best[k] == (catalogue.nearest_spp(name, spp, dims, strength) or 0), cases[k]


# ----------------------------------------------------------------------------- the message buffer

def test_messages_are_truncated_like_snprintf(lib):
    """For every buffer size from 0 to past the message: the same return
    code, the message's first size - 1 bytes and a 0, nothing written past
    the size (guard bytes), and a NULL buffer is fine."""
    long_cases = [("sobol", 100, None, None, None, None), ("jittered2d", 2, None, None, None, None),
                  ("bose", 0, None, None, None, None), ("zsobol", 16, None, None, None, None),
                  ("bush", 63, None, None, None, None), ("faure", 9, None, None, 4094, None),
                  ("zfaure", 30, None, None, None, HD), ("zfaure", 125, None, None, 2, HD),
                  ("zfaure", 4093**2, None, None, None, (4094, 1))]
    for name, spp, strength, dims, base, resolution in long_cases:
        rc, msg = expect(name, spp, strength, dims, base, resolution)
        assert rc != OK
        full = msg.encode()
        width, height = resolution or (0, 0)
        for size in range(0, len(full) + 3):
            raw = (ctypes.c_char * (size + 16))(*([b"\xaa"] * (size + 16)))
            got = lib.t_resolve(name.encode(), spp, strength or 0, dims or 0, None, base or 0, width, height,
                                (ctypes.c_uint32 * FIELDS)(), ctypes.byref(ctypes.c_uint32()), raw, ctypes.c_size_t(size))
            assert got == rc
            data = bytes(raw)
            assert data[size:] == b"\xaa" * 16, (name, size)
            if size:
                kept = full[: size - 1]
                assert data[: len(kept) + 1] == kept + b"\0", (name, size)
        assert lib.t_resolve(name.encode(), spp, 0, dims or 0, None, base or 0, width, height,
                             (ctypes.c_uint32 * FIELDS)(), ctypes.byref(ctypes.c_uint32()), None, ctypes.c_size_t(64)) == rc
    buf = ctypes.create_string_buffer(8)
    assert lib.t_name_error(b"nope", buf, 8) > 8 and buf.value == b"unknown"


# ----------------------------------------------------------------------------- the integer root

def test_the_exact_root_rounds_as_python_at_every_boundary(lib):
    """constructions._power_candidates starts from int(round(spp ** (1.0 /
    t))); the header computes that integer exactly. The two can only differ
    next to a rounding boundary (r + 1/2)^t: every count there, for every t
    in 2..24 and every count below 2^32, rounds the same way."""
    values, ts = [], []
    for t in range(2, 25):
        r = 1
        while r**t <= U32:
            edge = (2 * r + 1) ** t // 2**t
            for v in range(max(1, edge - 2), min(edge + 3, U32 + 1)):
                values.append(v)
                ts.append(t)
            r += 1
    values += [1, 2, 3, U32, MAX_SPP]
    ts += [2, 24, 3, 2, 24]
    v, t = np.asarray(values, np.uint32), np.asarray(ts, np.uint32)
    out = np.zeros(len(v), np.uint32)
    lib.t_root_round(ctypes.c_size_t(len(v)), *(a.ctypes.data_as(ctypes.c_void_p) for a in (v, t, out)))
    want = [int(round(int(x) ** (1.0 / int(e)))) for x, e in zip(values, ts)]
    assert out.tolist() == want
    assert len(values) > 100_000
