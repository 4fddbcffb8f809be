"""The OpenCL backend (pyoa._opencl.backend): launches, tables and buffer sizes."""

from __future__ import annotations

import numpy as np
import pytest

import pyoa
from tests.helpers import assert_same_bits, reference_block

pytestmark = pytest.mark.opencl


def test_chunk_limit_respects_device(opencl):
    from pyoa._opencl.backend import MAX_CHUNK_BYTES

    dev = opencl.info.device
    assert 0 < opencl.max_chunk_values * 4 <= min(MAX_CHUNK_BYTES, dev.max_mem_alloc_size, 2**31 - 1)


def test_no_device_buffer_exceeds_the_chunk_limit(monkeypatch, opencl):
    """Every device allocation of one launch (output chunk, permutation tables) must
    stay within the backend's chunk limit, which is how it honours the device's
    CL_DEVICE_MAX_MEM_ALLOC_SIZE. The permutation tables of the `cmj` path are
    n_pixels x n_dims x (s + M + 1) uint32 and are not bounded by it: on PoCL
    (max alloc 2 GiB) cmjnd spp=2^24, dims=64 fails with INVALID_BUFFER_SIZE
    although every output chunk is 256 MiB. Here the same with a small limit."""
    import pyopencl as cl

    sizes = []
    real = cl.Buffer

    def recording(ctx, flags, size=0, hostbuf=None):
        nbytes = hostbuf.nbytes if hostbuf is not None else size
        sizes.append(nbytes)
        return real(ctx, flags, size, hostbuf) if hostbuf is not None else real(ctx, flags, size)

    smp = pyoa.sampler("bose", spp=169, dims=100, seed=1, backend="opencl")  # cmj: tables of 27 entries
    want = pyoa.sampler("bose", spp=169, dims=100, seed=1, backend="numpy").generate(pixels=[0])
    limit_values = 2000
    monkeypatch.setattr(smp._backend, "max_chunk_values", limit_values)
    monkeypatch.setattr(cl, "Buffer", recording)
    got = smp.generate(pixels=[0])
    assert_same_bits(got, want)
    assert max(sizes) <= 4 * limit_values, f"largest device buffer {max(sizes)} B > chunk limit {4 * limit_values} B"


def test_tables_and_direct_kernels_agree(opencl):
    for offset in ("cmj", "centered"):
        smp = pyoa.sampler("bose", spp=121, dims=25, seed=6, offset=offset, backend="opencl")
        full = smp.generate(pixels=[0, 2**32 - 1])  # table kernels
        few = np.concatenate([smp.generate(pixels=[0, 2**32 - 1], samples=range(k, min(k + 10, 121)))
                              for k in range(0, 121, 10)], axis=1)  # 10 samples: direct kernel
        assert_same_bits(full, few, offset)


def test_index2_constants_and_fields_follow_each_sampler(opencl):
    """One backend object serves Addelman-Kempthorne of several orders (each with its
    own constants buffer, GF(9) tables or none) and Bose-Bush (GF(2s) tables, no
    constants), interleaved with Bose: every launch reads its own, for both kernels
    (the table path for cmj, the direct one for mj)."""
    cases = [("addelman-kempthorne", 18), ("addelman-kempthorne", 50), ("bose-bush", 8), ("bose", 64),
             ("addelman-kempthorne", 162), ("bose-bush", 32), ("addelman-kempthorne", 18), ("bose-bush", 8)]
    for offset in ("cmj", "mj"):
        for name, spp in cases:
            smp = pyoa.sampler(name, spp=spp, dims=9, seed=3, offset=offset, backend="opencl")
            assert smp._backend is opencl
            want = pyoa.sampler(name, spp=spp, dims=9, seed=3, offset=offset, backend="numpy").generate(pixels=[0, 5])
            assert_same_bits(smp.generate(pixels=[0, 5]), want, f"{name} spp={spp} {offset}")


@pytest.mark.parametrize("offset", ["cmj", "centered"])
def test_table_path_splits_long_axes_and_partial_pixels(monkeypatch, opencl, offset):
    """The table kernels have no bounds check, so _launch_2d covers an axis longer
    than one work-group with full groups plus a remainder launch at a global
    offset (Bose s=37: 1369 samples = 21 x 64 + 25). With a chunk of 1.5 pixels
    every chunk is a head, whole-pixel and tail rectangle, each on the table path.
    Same bits as NumPy, and as the reference at the seams. The table path is
    forced: ``auto`` takes the direct path on a GPU."""
    from pyoa.catalogue.request import Rect

    n = 1369
    kw = dict(spp=n, dims=7, seed=5, offset=offset)
    smp = pyoa.sampler("bose", backend="opencl", **kw)
    monkeypatch.setattr(smp._backend, "path", "tables")
    assert n > smp._backend._axis_limit and n % 64  # both launches of _launch_2d
    pixels = [3, 2**32 - 1, 0, 17]
    want = pyoa.sampler("bose", backend="numpy", **kw).generate(pixels=pixels)
    assert_same_bits(smp.generate(pixels=pixels), want, "whole pixels")

    monkeypatch.setattr(smp._backend, "max_chunk_values", 7 * (n + n // 2))
    launched = []
    real = smp._backend._launch_tabled
    monkeypatch.setattr(smp._backend, "_launch_tabled", lambda req, rect, *a: (launched.append(rect), real(req, rect, *a)))
    got = smp.generate(pixels=pixels)
    assert_same_bits(got, want, "chunks of 1.5 pixels")
    assert Rect(n + n // 2, 2 * n, 1, 2, n // 2, n) in launched  # a tail, tabled
    assert any(r.n_k == n and r.n_pixels == 1 for r in launched)
    seams = [0, n // 2 - 1, n // 2, n // 2 + 1, 1343, 1344, n - 1]
    assert_same_bits(got[:, seams], reference_block(smp, pixels, seams, range(7)), "vs reference")


# ----------------------------------------------------------------------------- hash keys: one definition

def _reference_keys() -> dict[str, int]:
    """Every ``NAME_KEY = 0x...`` assignment at the top level of a module of
    pyoa/reference, read from the source text (not through pyoa._opencl.program,
    whose collection this checks)."""
    import re
    from pathlib import Path

    import pyoa.reference

    keys = {}
    for path in sorted(Path(pyoa.reference.__file__).parent.glob("*.py")):
        for name, value in re.findall(r"^([A-Z][A-Z0-9_]*_KEY) = (0x[0-9A-Fa-f]+)\b", path.read_text(), re.MULTILINE):
            assert keys.get(name, int(value, 16)) == int(value, 16), f"{name} has two values"
            keys[name] = int(value, 16)
    return keys


#: Every hash key the kernels use: the *_KEY constants of pyoa/reference.
KERNEL_KEYS = _reference_keys()


def test_kernel_keys_come_from_the_generated_header_only():
    """The *_KEY values reach the kernels only through pyoa/keys.h, generated
    from the Python constants: its defines equal them, the program text holds
    it before any kernel, no build option, no other header and no .cl file
    defines a key, and every key a kernel names is one of them."""
    import re
    from importlib import resources

    from pyoa import kernels
    from pyoa._opencl import program

    want = dict(KERNEL_KEYS)
    assert want["PIXEL_KEY"] == 0x5BD1E995 and want["OWEN_KEY"] == 0xCC9E2D51  # the collection finds keys
    assert not [opt for opt in program.BUILD_OPTIONS if opt.startswith("-D")]
    keys_h = resources.files(kernels).joinpath("include", "pyoa", "keys.h").read_text()
    got = {m[1]: int(m[2], 16) for m in re.finditer(r"^#define PYOA_(\w+_KEY) 0x([0-9a-f]{8})u$", keys_h, re.MULTILINE)}
    assert got == want

    cl_files = sorted(p for p in resources.files(kernels).iterdir() if p.name.endswith(".cl"))
    assert {p.name for p in cl_files} >= set(kernels.SOURCES)
    headers = [p for p in resources.files(kernels).joinpath("include", "pyoa").iterdir()
               if p.name.endswith((".h", ".hpp")) and p.name != "keys.h"]
    for path in [*cl_files, *headers]:
        text = path.read_text()
        defined = re.findall(r"^\s*#\s*define\s+(\w*_KEY)\b", text, re.MULTILINE)
        assert not defined, f"{path.name} defines {defined}: keys come from pyoa/keys.h only"
    source = program.source()
    assert source.index("PYOA_PIXEL_KEY 0x") < source.index("---- pyoa/hashes.h")
    # every key a kernel names is in keys.h; a reference key no kernel uses
    # (pmj02's table-builder keys) is there but need not be used
    used = set(re.findall(r"\bPYOA_([A-Z][A-Z0-9_]*_KEY)\b", source.replace(keys_h, "")))
    assert used <= set(want) and {"PIXEL_KEY", "OWEN_KEY", "ZSOBOL_KEY", "PMJ02_KEY"} <= used


