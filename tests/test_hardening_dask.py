"""Hardening of ``Sampler.to_dask`` and ``pyoa backends`` (issue 33, items 6,
9 and 15): chunk sizes that Dask would keep or misread are refused with the
axis and the valid forms, the graph is built lazily and a chunk count past
``MAX_DASK_CHUNKS`` is refused before anything is listed (checked in a child
process under a memory cap), and a bad ``$PYOA_BACKEND`` makes ``pyoa
backends`` exit 2 as every other command does."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import pyoa

pytest.importorskip("dask.array")

FORMS = "valid chunks: 'auto', a size such as '64MiB', an int >= 1"


@pytest.fixture(scope="module")
def smp():
    return pyoa.sampler("bose", spp=49, dims=8, seed=7, backend="numpy")


# -- item 6: chunks Dask keeps or misreads --------------------------------------------------------

BAD_CHUNKS = [
    # Dask keeps negative sizes: the array declared 10 pixels and computed 13
    (((5, -3, 8), -1, -1), ValueError, "pixels axis must be ints >= 1 adding up to its length 10, got (5, -3, 8)"),
    ((-1, (25, 25, -1), -1), ValueError, "samples axis must be ints >= 1 adding up to its length 49"),
    (((10, 0), -1, -1), ValueError, "pixels axis must be ints >= 1"),
    # Dask divides by zero
    (0, ValueError, "chunks for the pixels axis must be >= 1, or -1 for the whole axis, got 0"),
    ((-1, 0, -1), ValueError, "chunks for the samples axis must be >= 1, or -1 for the whole axis, got 0"),
    ({2: 0}, ValueError, "chunks for the dims axis must be >= 1"),
    # Dask's message says nothing of the axis or the forms
    (-2, ValueError, "chunks for the pixels axis must be >= 1, or -1 for the whole axis, got -2"),
    # Dask truncates floats ((2.5, 7.5) adds up to 10, and made 9 pixels of chunks (2, 7)) and reads True as 1
    (((2.5, 7.5), -1, -1), TypeError, "chunk sizes of the pixels axis must be ints, got float 2.5"),
    ((4, 2.0, -1), TypeError, "chunks for the samples axis must be an int, None, 'auto' or a tuple of ints"),
    (True, TypeError, "got bool True"),
    # Dask ignores an axis that does not exist
    ({5: 1}, ValueError, "needs axis 0 (pixels), 1 (samples) or 2 (dims), got 5"),
]


@pytest.mark.parametrize("chunks, error, words", BAD_CHUNKS, ids=[repr(c) for c, _, _ in BAD_CHUNKS])
def test_bad_chunks_name_the_axis_and_the_forms(smp, chunks, error, words):
    with pytest.raises(error) as exc:
        smp.to_dask(pixels=range(10), chunks=chunks)
    assert words in str(exc.value) and FORMS in str(exc.value), str(exc.value)


def test_good_chunks_still_give_generates_bits(smp):
    want = smp.generate(pixels=range(10)).view(np.uint32)
    for chunks in [((5, 5), -1, -1), (np.int64(3), None, -1), [3, 5, 2], {1: 7}, "4KiB", None]:
        arr = smp.to_dask(pixels=range(10), chunks=chunks)
        assert np.array_equal(arr.compute().view(np.uint32), want), chunks


# -- item 9: the graph's size -----------------------------------------------------------------------

#: Address space the child may add while building one array: the lazy graph
#: takes about 64 MiB at a million chunks (Dask's record of the chunks), a
#: graph of one task per chunk took 225 MiB at half a million.
BUILD_CAP = 128 << 20

#: key -> (sampler keyword arguments, pixels, chunks) of each array built in the child
BUILDS = {
    "refused": ({}, 10**7, (1, -1, -1)),
    "lazy": ({}, 500_000, (1, -1, -1)),
    "suggested": ({}, 10**7, (10, -1, -1)),  # what the refusal of "refused" suggests
    "auto_tiny": ({"max_bytes": "64KiB"}, 2**32, "auto"),  # "auto" chunks of at most 32 KiB
}

CHILD = """
    import json, resource, sys, time
    import numpy as np, pyoa, dask.array

    def vm():
        return int(next(l for l in open("/proc/self/status") if l.startswith("VmSize")).split()[1]) * 1024

    cap, builds = json.loads(sys.argv[1])
    base = pyoa.sampler("bose", spp=49, dims=8, seed=7, backend="numpy")
    base.to_dask(pixels=range(4), chunks=(1, -1, -1)).compute()  # every import and thread pool made before the cap
    hard = resource.getrlimit(resource.RLIMIT_AS)[1]
    report = {}
    for key, (kwargs, n, chunks) in builds.items():
        smp = pyoa.sampler("bose", spp=49, dims=8, seed=7, backend="numpy", **kwargs)
        chunks = tuple(chunks) if isinstance(chunks, list) else chunks
        resource.setrlimit(resource.RLIMIT_AS, (vm() + cap, hard))
        t = time.perf_counter()
        try:
            arr = smp.to_dask(pixels=range(n), chunks=chunks)
            out = {"numblocks": list(arr.numblocks), "layers": len(arr.dask.layers)}
        except BaseException as exc:
            arr, out = None, {"error": type(exc).__name__, "message": str(exc)}
        out["seconds"] = time.perf_counter() - t
        resource.setrlimit(resource.RLIMIT_AS, (hard, hard))
        if arr is not None and key == "lazy":
            got = arr[-3:].compute()
            out["same_bits"] = bool(np.array_equal(got.view(np.uint32),
                                                   smp.generate(pixels=range(n - 3, n)).view(np.uint32)))
        del arr
        report[key] = out
    print(json.dumps(report))
"""


@pytest.fixture(scope="module")
def graph_report():
    """What building each array of BUILDS did in a child process, each build
    under RLIMIT_AS of the child's size then + BUILD_CAP (a graph built
    eagerly runs out of memory instead of exhausting the machine)."""
    res = subprocess.run([sys.executable, "-c", textwrap.dedent(CHILD), json.dumps([BUILD_CAP, BUILDS])],
                         capture_output=True, text=True, timeout=120, env={**os.environ, "PYOA_BACKEND": "numpy"})
    assert res.returncode == 0, res.stderr[-2000:]
    return json.loads(res.stdout.splitlines()[-1])


def test_too_many_chunks_are_refused_before_any_is_listed(graph_report):
    got = graph_report["refused"]
    assert got.get("error") == "ValueError", got  # a graph of one task per chunk: MemoryError after 47 s
    assert "chunks=(1, -1, -1) makes 10,000,000 chunks of the 10000000 x 49 x 8 array, over the 1,000,000" \
        in got["message"], got
    assert "e.g. chunks=(10, -1, -1)" in got["message"], got
    assert got["seconds"] < 1, got


def test_the_graph_is_one_lazy_layer(graph_report):
    got = graph_report["lazy"]
    assert "error" not in got, got
    assert got["numblocks"] == [500_000, 1, 1] and got["layers"] == 2, got
    assert got["same_bits"], got
    got = graph_report["suggested"]  # the chunking that the refusal of 10**7 one-pixel chunks suggests
    assert "error" not in got and got["numblocks"] == [10**6, 1, 1], got


def test_auto_chunks_with_a_tiny_memory_limit_are_counted_first(graph_report):
    got = graph_report["auto_tiny"]
    count = -(-(2**32 * 49 * 8 * 4) // (32 << 10))  # "auto" chunks are at most half of max_bytes
    assert got.get("error") == "ValueError", got
    assert f"chunks='auto' makes about {count:,} chunks" in got["message"], got
    assert "raise the memory limit of a chunk with max_bytes=" in got["message"], got


# -- item 15 (part): pyoa backends with a bad $PYOA_BACKEND ------------------------------------------


def test_backends_refuses_a_bad_environment_backend():
    res = subprocess.run([sys.executable, "-m", "pyoa", "backends"], capture_output=True, text=True, timeout=120,
                         env={**os.environ, "PYOA_BACKEND": "garbage"})
    assert res.returncode == 2, (res.returncode, res.stdout, res.stderr)
    assert res.stdout == "" and "Traceback" not in res.stderr
    assert res.stderr.splitlines() == ["pyoa backends: error: unknown $PYOA_BACKEND 'garbage'; valid: opencl, "
                                       "numpy (or unset it for automatic)"], res.stderr
