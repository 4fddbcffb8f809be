"""The catalogue-driven suites: every registered sampler, by being registered.

Each entry of :data:`pyoa.catalogue.SAMPLERS` names its three implementations
and its test shapes (``test_cases``) and guarantees (``claims``). From those
alone this module checks, for every entry:

- conformance: the OpenCL kernels and NumPy give the bits of the pure-Python
  reference on blocks with the edge cases (first and last pixel, sample and
  dimension; seeds 0 and 2**32 - 1; every offset and a jitter with many
  bits), on hypothesis-drawn blocks, and however a request is chunked;
- properties: every claim of every shape small enough to enumerate, checked
  exactly on the float32 values (``floor(x * n)`` is exact in float64);
- registration: codes, the generated kernel dispatch (an unregistered code
  gives NaN, never another sampler's values) and the name lists of the docs.

A new sampler gets all of this by being registered; the deeper suites of
the existing samplers (tests/test_conformance.py, test_baselines*.py) remain.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import pyoa
from pyoa import catalogue
from pyoa.catalogue.baselines import Baseline
from pyoa.catalogue.entries import REGISTRY, Claim
from pyoa.catalogue.params import FaureParams, OAParams, PointSetParams, SequenceParams
from tests.helpers import U32_MAX, assert_same_bits, net_failures, reference_block

ROOT = Path(__file__).resolve().parent.parent
ENTRIES = list(catalogue.SAMPLERS.values())
#: (entry name, sampler kwargs) of every test case of every entry
CASES = [(c.name, kw) for c in ENTRIES for kw in c.test_cases()]
#: a jitter with many significant bits (a fused multiply-add would change them)
JITTER = float(np.float32(1 / 3))
#: largest point set the property suite enumerates (per pixel, all dims)
PROPERTY_VALUES = 1 << 20


def case_id(case) -> str:
    name, kw = case
    return f"{name}-" + "-".join(f"{k}{v if not isinstance(v, tuple) else 'x'.join(map(str, v))}"
                                 for k, v in kw.items())


def variants(name: str):
    """(offset, jitter) pairs that change a sampler of ``name``: every offset
    of the OAs (at a jitter with many bits, and 'cmj' at 1), a jitter for the
    jittered comparison samplers."""
    entry = catalogue.get(name)
    if entry.offsets:
        return [(entry.default_offset, 1.0)] + [(o, JITTER) for o in entry.offsets]
    return [(None, 1.0)] + ([(None, JITTER)] if entry.jittered else [])


def make(name, kw, backend, seed=0, offset=None, jitter=1.0):
    return pyoa.sampler(name, seed=seed, offset=offset, jitter=jitter, backend=backend, **kw)


def edge_indices(n: int, k: int = 2) -> list[int]:
    """The first ``k``, the middle and the last ``k`` of ``range(n)``."""
    return sorted({*range(min(k, n)), n // 2, *range(max(0, n - k), n)})


# ----------------------------------------------------------------------------- registration

def test_every_entry_is_complete_and_its_cases_resolve():
    codes = [c.code for c in ENTRIES]
    assert len(set(codes)) == len(codes), "two entries share a kernel code"
    for c in ENTRIES:
        assert callable(type(c).reference) and callable(type(c).numpy) and c.kernel, c.name
        assert c.test_cases(), f"{c.name} has no test cases"
        for kw in c.test_cases():
            smp = pyoa.sampler(c.name, backend="numpy", **kw)
            assert smp.spp == kw["spp"] and smp.dims == kw["dims"]


#: The parameter type each family resolves to (pyoa.catalogue.params), per entry class.
PARAMETER_TYPES = {"bose": OAParams, "bush": OAParams, "cmjnd": OAParams, "addelman-kempthorne": OAParams,
                   "bose-bush": OAParams, "jittered2d": PointSetParams, "cmj2d": PointSetParams,
                   "faure": FaureParams, "zfaure": FaureParams}


@pytest.mark.parametrize("name, kw", CASES, ids=map(case_id, CASES))
def test_parameters_are_of_the_family_type_and_give_the_sampler_again(name, kw):
    """Every test case resolves to its family's parameter type (any other
    comparison sampler: a sequence), whose count is the sampler's; the
    listing's s, strength and block_dims are the sampler's; and the keywords
    ``arguments`` names (a resolved strength, base or image) give the same
    parameters at any dims (a copy cannot resolve others)."""
    entry = catalogue.get(name)
    smp = pyoa.sampler(name, backend="numpy", **kw)
    prm = smp.params
    assert type(prm) is PARAMETER_TYPES.get(name, SequenceParams) and prm.N == smp.spp
    shown = entry.choice(prm)
    assert (shown.spp, shown.s, shown.strength, shown.block_dims) == (smp.spp, smp.s, smp.strength, smp.block_dims)
    again = {k: v for k, v in kw.items() if k not in ("strength", "base", "resolution")}
    assert pyoa.sampler(name, backend="numpy", **{**again, **entry.arguments(prm)}).params == prm
    assert entry.choice(pyoa.sampler(name, backend="numpy", **{**again, "dims": 1, **entry.arguments(prm)}).params) \
        == shown


def test_family_is_read_only_to_list_samplers():
    """No module of pyoa branches on an entry's family (its family's class
    answers instead), and faure is no comparison sampler: the catalogue
    lists every registered entry, grouped by family."""
    compared = re.compile(r"family\s*(==|!=)|family\s+(not\s+)?in\b")
    found = [f"{p.relative_to(ROOT)}:{k}" for p in sorted((ROOT / "pyoa").rglob("*.py"))
             for k, line in enumerate(p.read_text().splitlines(), 1) if compared.search(line)]
    assert not found, f"family compared in {found}"
    assert not isinstance(catalogue.get("faure"), Baseline)
    assert list(catalogue.SAMPLERS) == [n for f in catalogue.FAMILY_ORDER for n in catalogue.names(f)]
    assert set(catalogue.SAMPLERS) == set(REGISTRY)


def test_register_refuses_a_taken_name_or_code():
    from pyoa.catalogue import entries as ct

    bose = type(catalogue.get("bose"))
    with pytest.raises(ValueError, match="registered twice"):
        ct.register(bose)
    clash = type("Clash", (bose,), {"name": "clash"})
    with pytest.raises(ValueError, match="kernel code 0 is already bose's"):
        ct.register(clash)
    assert "clash" not in ct.REGISTRY
    bare = type("Bare", (bose,), {"name": "bare", "code": 999, "kernel": ""})
    with pytest.raises(TypeError, match="C function in the headers"):
        ct.register(bare)


def test_every_entry_names_a_header_function_its_dispatch_calls():
    """An entry's ``kernel`` names its C function in the portable headers;
    the header's dispatch (pyoa_oa_value in oa.h, pyoa_baseline_value in
    values.h) calls it under the entry's code, keys.h defines that code
    from the catalogue, and generate.cl has the entry's kernel. A new entry
    without all four fails here."""
    include = ROOT / "kernels" / "include" / "pyoa"
    headers = "\n".join(p.read_text() for p in sorted(include.glob("*.h")))
    oa = (include / "oa.h").read_text()
    values = (include / "values.h").read_text()
    keys = (include / "keys.h").read_text()
    gen = (ROOT / "kernels" / "generate.cl").read_text()
    for c in ENTRIES:
        code = f"PYOA_SAMPLER_{c.function.upper()}"
        assert re.search(rf"#define {code} {c.code}u\b", keys), c.name
        assert re.search(rf"PYOA_FN \w+ {c.kernel}\(", headers), f"{c.kernel} is not a header function"
        if c.family == "oa":
            assert re.search(rf"case {code}: {c.kernel}\(", re.sub(r"\s+", " ", oa)), c.name
        else:
            assert re.search(rf"case {code}: return {c.kernel}\(", values), c.name
            assert f"GENERATE_BASELINE({c.function}, {code})" in gen, c.name
    # one block rule and one tail for every construction, and nothing per
    # construction left in the OpenCL sources
    assert oa.count("pyoa_oa_locate(p,") == 1 and oa.count("return pyoa_oa_tail(") == 1
    assert not re.search(r"pyoa_\w+_cell\(", gen)


def test_an_unregistered_code_gives_nan(opencl):
    """The dispatch's default: a code no entry has gives NaN, not cmjnd's
    (or anyone's) values."""
    from tests.helpers import kernel_runner

    run = kernel_runner(opencl, """
__kernel void t_dispatch(__global const uint *code, __global const ushort *gf, __global const uint *consts,
                         __global float *out)
{
    uint g = get_global_id(0);
    out[g] = pyoa_oa_value(code[g], 3u, 1u, 5u, 2u, 6u, 25u, 5u, 12345u, PYOA_OFFSET_CMJ, 1.0f, gf, 0u, consts);
}
""")
    codes = np.array([catalogue.get("cmjnd").code, catalogue.get("bose").code, 999, 0xFFFFFFFF], np.uint32)
    got = run("t_dispatch", [np.float32], codes, np.zeros(4, np.uint16), np.zeros(4, np.uint32))
    assert np.isfinite(got[:2]).all() and np.isnan(got[2:]).all()


def test_name_lists_of_the_docs_follow_the_catalogue():
    """The README's sampler tables, docs/samplers.md's table and the
    docstrings that list names hold exactly the registered samplers."""
    names = set(catalogue.SAMPLERS)
    readme = (ROOT / "README.md").read_text()
    table_names = set(re.findall(r"^\| `([a-z0-9-]+)` \|", readme.split("## Samplers", 1)[1].split("\n## ", 1)[0],
                                 re.MULTILINE))
    assert table_names == names, f"README tables: missing {names - table_names}, extra {table_names - names}"
    doc = (ROOT / "docs" / "samplers.md").read_text()
    rows = set(re.findall(r"^\| `([a-z0-9-]+)` \|", doc, re.MULTILINE))
    assert rows == set(catalogue.names("baseline")), f"docs/samplers.md's table: {rows} != the comparison samplers"
    for text, where in ((pyoa.sampler.__doc__, "pyoa.sampler"), (pyoa.Sampler.__doc__, "pyoa.Sampler")):
        missing = {n for n in names if f'"{n}"' not in text and f"``{n}``" not in text}
        assert not missing, f"{where}'s docstring does not name {missing}"
    assert set(pyoa.samplers()) == names


# ----------------------------------------------------------------------------- conformance

@pytest.mark.parametrize("case", CASES, ids=case_id)
def test_edges_match_the_reference(backend, case):
    """First/middle/last pixel, sample and dimension, both extreme seeds, every
    variant: the backend's bits are the reference's."""
    name, kw = case
    for seed in (0, U32_MAX):
        for offset, jitter in variants(name):
            smp = make(name, kw, backend, seed, offset, jitter)
            pixels = edge_indices(min(smp.n_pixels, 2**32), 1)
            samples = edge_indices(smp.spp)
            dims = edge_indices(smp.dims)
            got = smp.generate(pixels=pixels, samples=samples, dims=dims)
            assert_same_bits(got, reference_block(smp, pixels, samples, dims),
                             f"{name} {kw} seed {seed} {offset} {jitter}")
            assert smp.value(pixels[-1], samples[-1], dims[-1]) == got[-1, -1, -1]


@st.composite
def blocks(draw):
    name, kw = draw(st.sampled_from(CASES))
    offset, jitter = draw(st.sampled_from(variants(name)))
    seed = draw(st.sampled_from([0, 1, U32_MAX]) | st.integers(0, U32_MAX))
    smp = make(name, kw, "numpy", seed, offset, jitter)
    top = min(smp.n_pixels, 2**32) - 1
    pixels = draw(st.lists(st.integers(0, top) | st.sampled_from([0, top]), min_size=1, max_size=3))
    samples = draw(st.lists(st.integers(0, smp.spp - 1), min_size=1, max_size=5))
    dims = draw(st.lists(st.integers(0, smp.dims - 1), min_size=1, max_size=4))
    return smp, pixels, samples, dims


@settings(max_examples=60, deadline=None)
@given(blocks())
def test_numpy_matches_the_reference_on_random_blocks(block):
    smp, pixels, samples, dims = block
    assert_same_bits(smp.generate(pixels=pixels, samples=samples, dims=dims),
                     reference_block(smp, pixels, samples, dims), repr(smp))


@settings(max_examples=60, deadline=None)
@given(block=blocks())
def test_opencl_matches_numpy_on_random_blocks(opencl, block):
    smp, pixels, samples, dims = block
    kw = smp._arguments() | {"backend": "opencl"}
    other = pyoa.sampler(smp.name, **kw)
    assert_same_bits(other.generate(pixels=pixels, samples=samples, dims=dims),
                     smp.generate(pixels=pixels, samples=samples, dims=dims), repr(smp))


@pytest.mark.parametrize("case", CASES, ids=case_id)
def test_opencl_matches_numpy_in_bulk_and_chunks(opencl, monkeypatch, case):
    """Whole pixels of up to 4,096 samples, all variants; then the same request
    in chunks that split pixels (the rectangles of every path)."""
    name, kw = case
    for offset, jitter in variants(name):
        a = make(name, kw, "numpy", 7, offset, jitter)
        b = make(name, kw, "opencl", 7, offset, jitter)
        n_pix = min(3, a.n_pixels)
        samples = range(min(a.spp, 4096)) if a.spp <= 4096 else edge_indices(a.spp, 300)
        dims = range(min(a.dims, 12)) if a.dims <= 12 else edge_indices(a.dims, 4)
        want = a.generate(pixels=range(n_pix), samples=samples, dims=dims)
        assert_same_bits(b.generate(pixels=range(n_pix), samples=samples, dims=dims), want, f"{name} {kw} {offset}")
        rows = n_pix * len(samples)
        with monkeypatch.context() as m:
            m.setattr(b._backend, "rows_per_chunk", lambda n_dims: max(1, rows // 3 + 1))
            assert_same_bits(b.generate(pixels=range(n_pix), samples=samples, dims=dims), want, "chunked")


# ----------------------------------------------------------------------------- properties

def _strata(x, n):
    return np.floor(np.asarray(x, np.float64) * n).astype(np.int64)


def check_claim(claim: Claim, x: np.ndarray, what: str) -> None:
    """Check one claim on ``x`` of shape (pixels, N, dims), exactly."""
    P, N, D = x.shape
    if claim.kind == "oa":
        s, t, B = claim.s, claim.strength, claim.block_dims
        lam = N // s**t
        st_ = _strata(x, s)
        import itertools

        for b0 in range(0, D, B):
            cols = range(b0, min(D, b0 + B))
            for sub in itertools.combinations(cols, min(t, len(cols))):
                code = np.zeros((P, N), np.int64)
                for c in sub:
                    code = code * s + st_[:, :, c]
                cells = s ** len(sub)
                counts = np.stack([np.bincount(code[p], minlength=cells) for p in range(P)])
                assert (counts == N // cells).all() and N // cells >= lam, f"{what}: columns {sub} not an OA"
    elif claim.kind == "latin":
        n = claim.n
        counts = np.stack([np.stack([np.bincount(_strata(x[p, :, d], n), minlength=n) for d in range(D)])
                           for p in range(P)])
        assert counts.shape[-1] == n and (counts == N // n).all(), f"{what}: not {n} strata of {N // n}"
    elif claim.kind == "grid":
        a, c = claim.a, claim.c
        for d in range(0, D - 1, 2):
            code = _strata(x[:, :, d], a) * c + _strata(x[:, :, d + 1], c)
            counts = np.stack([np.bincount(code[p], minlength=a * c) for p in range(P)])
            assert counts.shape[-1] == a * c and (counts == N // (a * c)).all(), f"{what}: pair {d} not a grid"
    elif claim.kind == "net":
        k = claim.n.bit_length() - 1
        pairs = range(0, D - 1, 2) if not claim.pairs else range(0, min(D - 1, 2 * claim.pairs), 2)
        lengths = [1 << m for m in range(k + 1)] if claim.prefixes else [claim.n]
        for d in pairs:
            for n in lengths:
                m = n.bit_length() - 1
                for u in range(m + 1):
                    code = _strata(x[:, :n, d], 1 << u) << (m - u) | _strata(x[:, :n, d + 1], 1 << (m - u))
                    counts = np.stack([np.bincount(code[p], minlength=n) for p in range(P)])
                    assert counts.shape[-1] == n and (counts == 1).all(), \
                        f"{what}: pair {d}, first {n}: not a (0,{m},2)-net at 2^-{u} x 2^-{m - u}"
    elif claim.kind == "faure":
        # every aligned block of b^m samples a (0,m,s)-net in base b, m <= strength
        # (which makes every prefix of lam b^m samples hold lam points per box)
        for m in range(1, claim.strength + 1):
            fails = net_failures(x, claim.s, m, claim.block_dims)
            assert not fails, f"{what}: blocks of {claim.s}^{m} not nets at {fails[:3]}"
    else:  # pragma: no cover - a claim kind this suite does not know is a test failure
        raise AssertionError(f"{what}: unknown claim kind {claim.kind!r}")


PROPERTY_CASES = [(n, kw) for n, kw in CASES if kw["spp"] * kw["dims"] <= PROPERTY_VALUES]


@pytest.mark.parametrize("case", PROPERTY_CASES, ids=case_id)
def test_claims_hold(case):
    """Every claim of the entry, for 3 pixels (and 2 seeds) of every variant."""
    name, kw = case
    entry = catalogue.get(name)
    for seed in (0, 99):
        for offset, jitter in variants(name):
            smp = make(name, kw, "numpy", seed, offset, jitter)
            x = smp.generate(pixels=edge_indices(min(smp.n_pixels, 2**32), 1))
            assert ((x >= 0) & (x < 1)).all()
            for claim in entry.claims(smp.params, offset):
                check_claim(claim, x, f"{name} {kw} seed {seed} {offset}: {claim.kind}")


def test_every_entry_has_a_property_case():
    """An entry whose shapes are all too large to enumerate would escape the claims."""
    assert {n for n, _ in PROPERTY_CASES} == set(catalogue.SAMPLERS)


def test_claims_fail_on_wrong_points():
    """The checks can fail: uniform random points break each kind of claim."""
    rng = np.random.default_rng(1)
    x = rng.random((2, 64, 4)).astype(np.float32)
    for claim in (Claim("oa", s=8, strength=2, block_dims=4), Claim("latin", n=64), Claim("grid", a=8, c=8),
                  Claim("net", n=64), Claim("faure", n=64, s=2, strength=3, block_dims=4)):
        with pytest.raises(AssertionError):
            check_claim(claim, x, claim.kind)
    assert math.isqrt(64) == 8


# -- the names pbrt-v4 and Mitsuba 3 users type ----------------------------------------------------


def test_pbrt_and_mitsuba_names_are_accepted_and_listed():
    import pyoa
    from pyoa.qmc import OrthogonalArray, PyoaEngine

    for alias, (name, where) in catalogue.ALIASES.items():
        assert alias not in catalogue.SAMPLERS  # an alias never hides a pyoa name
        assert catalogue.get(alias) is catalogue.SAMPLERS[name]
        assert catalogue.get(alias.upper()) is catalogue.SAMPLERS[name]
        assert f"{alias} ({where})" in pyoa.samplers()[name]
    spp = {"random": 16, "jittered2d": 16, "cmj2d": 16, "bose": 16, "sobol02": 16}
    for alias, (name, _) in catalogue.ALIASES.items():
        a = pyoa.sampler(alias, spp=spp[name], dims=4, seed=3)
        assert a.name == name  # it carries the pyoa name
        np.testing.assert_array_equal(a.generate(pixels=range(3)),
                                      pyoa.sampler(name, spp=spp[name], dims=4, seed=3).generate(pixels=range(3)))
    assert set(pyoa.samplers()) == set(catalogue.SAMPLERS)  # listing them adds no sampler twice
    readme = " ".join((ROOT / "README.md").read_text().split())
    for alias, (name, _) in catalogue.ALIASES.items():
        assert f"`{alias}`" in readme and f"(`{name}`)" in readme
    with pytest.raises(ValueError, match=r"or the pbrt/Mitsuba names independent, stratified"):
        catalogue.get("nosuch")
    # the scipy engine: a neutral name for any sampler, the first one kept
    e, o = PyoaEngine(d=3, sampler="independent", spp=16, rng=5), OrthogonalArray(d=3, sampler="random", spp=16, rng=5)
    np.testing.assert_array_equal(e.random(32), o.random(32))
    assert repr(e).startswith("PyoaEngine(d=3, spp=16, sampler='random'")
    assert repr(o).startswith("OrthogonalArray(d=3")
