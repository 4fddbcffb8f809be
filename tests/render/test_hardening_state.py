"""State files, the scene's memory and Ctrl-C (issue 33, items 8, 14 and 15).

- A state file (``OUT.state.npz`` of ``pyoa render --progressive`` and of
  ``pyoa reference``) that is not a regular file is refused in one line,
  neither read (``/dev/zero`` never ends, a FIFO blocks) nor replaced; a
  forged ``.npy`` header claiming a huge array is refused (progressive) or
  not resumed (reference) before anything is allocated from it; a state of
  another ``--size`` says so.
- A scene whose meshes need more memory than ``$PYOA_MAX_BYTES`` is refused
  before it is loaded or traced, and a MemoryError that still happens is one
  line, not a traceback.
- SIGINT (Ctrl-C) ends ``pyoa render`` and ``pyoa study`` with one line
  saying what was kept, exit status 130, and complete outputs.

Every command runs in a child process, under the memory cap of limits.py
and a timeout, so that a hang or an allocation without bound fails its test
(the two library refusals, of a tiny scene, run in-process).
"""

from __future__ import annotations

import io
import json
import os
import re
import resource
import shutil
import signal
import stat
import subprocess
import sys
import textwrap
import time
import zipfile

import numpy as np
import pytest

from pyoa.render.image import read_image, write_exr
from pyoa.render.integrator import RENDERER_VERSION
from pyoa.render.progressive import render_progressive, state_path
from pyoa.render.reference import Passes, reference_key
from pyoa.render.render import SCENE_TRIANGLE_BYTES, plan, render
from pyoa.render.scene import MESH_FILE_FACTOR, MESH_KEPT_BYTES, MESH_TRIANGLE_BYTES, SceneError, bundled, load
from pyoa.render.state import write_state
from pyoa.util.units import format_bytes

from .limits import python_child
from .test_hardening_cli import OLD, refused

#: Seconds a child may run: the refusals take about one, and a state that
#: blocks or never ends (a FIFO, /dev/urandom) fails the test instead of CI.
TIMEOUT = 60
#: The quickest settings to start: no OpenCL device, no numba compilation.
FAST = ["--backend", "numpy", "--shading", "numpy"]
PROGRESSIVE = ["render", "cornell", "--sampler", "sobol", "--spp", "2", "--progressive", "--resume", *FAST]
REFERENCE = ["reference", "cornell", "--spp", "4", "--pass-spp", "4", *FAST]


def pyoa(argv, limit, env=None, popen: bool = False):
    """``python -m pyoa argv`` under RLIMIT_AS = ``limit``, with ``env`` added
    to the environment (``$PYOA_MAX_BYTES`` unset unless given); returns the
    CompletedProcess, or with ``popen`` the running Popen (text pipes)."""

    def cap():
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))

    env = {**{k: v for k, v in os.environ.items() if k != "PYOA_MAX_BYTES"}, **(env or {})}
    cmd = [sys.executable, "-m", "pyoa", *map(str, argv)]
    if popen:
        return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                                preexec_fn=cap)
    return subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=TIMEOUT, preexec_fn=cap)


def snapshot(*paths):
    """Bytes (or kind) and mtime of each path, to show that a refused command left them alone."""
    out = []
    for p in paths:
        st = os.lstat(p)
        body = p.read_bytes() if stat.S_ISREG(st.st_mode) else (stat.S_IFMT(st.st_mode), os.readlink(p)
                                                                 if p.is_symlink() else None)
        out.append((body, st.st_mtime_ns))
    return out


def forge(state, member: str, shape, descr: str = "<f8") -> None:
    """Replace ``member`` of the state with a .npy header claiming ``shape``
    of type ``descr`` followed by 64 bytes (the other members kept as they are)."""
    with zipfile.ZipFile(state) as zf:
        members = {i.filename: zf.read(i) for i in zf.infolist()}
    head = io.BytesIO()
    np.lib.format.write_array_header_1_0(head, {"descr": descr, "fortran_order": False, "shape": shape})
    members[member] = head.getvalue() + bytes(64)
    with zipfile.ZipFile(state, "w") as zf:
        for name, data in members.items():
            zf.writestr(name, data)


# -- state files that are not regular files (item 8) ----------------------------------------------


NOT_REGULAR = {
    "symlink to /dev/zero": (lambda p: p.symlink_to("/dev/zero"), r"a symlink to '/dev/zero', a character device"),
    "symlink to /dev/urandom": (lambda p: p.symlink_to("/dev/urandom"),
                                r"a symlink to '/dev/urandom', a character device"),
    "FIFO": (os.mkfifo, r"a FIFO \(named pipe\)"),
    "directory": (lambda p: p.mkdir(), r"a directory"),
}


CASES = [(command, name) for name in NOT_REGULAR for command in ("progressive", "reference")]


@pytest.fixture(scope="module")
def not_regular(tmp_path_factory, as_limit):
    """Every case of NOT_REGULAR for both commands, run at once (each child is
    half a second of imports): (command, name) -> (result, out, snapshot before)."""
    started = {}
    for command, name in CASES:
        out = tmp_path_factory.mktemp("state") / "out.exr"
        out.write_bytes(OLD)
        NOT_REGULAR[name][0](state_path(out))
        argv = PROGRESSIVE if command == "progressive" else REFERENCE
        started[command, name] = (pyoa([*argv, "--size", "8", "8", "--out", out, "-q"], as_limit, popen=True), out,
                                  snapshot(out, state_path(out)))
    results = {}
    for case, (child, out, before) in started.items():
        try:
            stdout, stderr = child.communicate(timeout=TIMEOUT)
        except subprocess.TimeoutExpired:  # a hang is a failure of its own case, not of the others
            child.kill()
            stdout, stderr = child.communicate()
        results[case] = (subprocess.CompletedProcess(child.args, child.returncode, stdout, stderr), out, before)
    return results


@pytest.mark.parametrize("command, name", CASES, ids=[f"{n}-{c}" for c, n in CASES])
def test_a_state_that_is_not_a_regular_file_is_refused(not_regular, command, name):
    res, out, before = not_regular[command, name]
    whose = "a progressive render" if command == "progressive" else "pyoa reference"
    refused(res, "render" if command == "progressive" else "reference",
            rf"out\.exr\.state\.npz' \(where {whose} keeps its running sum\) is {NOT_REGULAR[name][1]}, not a "
            r"regular file; remove or rename it")
    assert snapshot(out, state_path(out)) == before  # neither read nor replaced, --out untouched


# -- forged headers and other sizes (items 8 and 15) ------------------------------------------------


@pytest.fixture(scope="module")
def progressive_state(tmp_path_factory):
    """A 16 x 16 progressive render of one sample (sobol) and its state."""
    out = tmp_path_factory.mktemp("progressive") / "out.exr"
    render_progressive(load("cornell"), out=out, sampler="sobol", spp=1, width=16, height=16, backend="numpy",
                       shading="numpy")
    return out


def copy_progressive(progressive_state, tmp_path):
    out = tmp_path / "out.exr"
    shutil.copy(progressive_state, out)
    shutil.copy(state_path(progressive_state), state_path(out))
    return out, state_path(out)


def test_a_forged_header_of_a_progressive_state_is_refused(progressive_state, tmp_path, as_limit):
    """Its sum claims 40000 x 40000 pixels (36 GB) in a few bytes: refused from the header, nothing allocated."""
    out, state = copy_progressive(progressive_state, tmp_path)
    forge(state, "sum.npy", (40000, 40000, 3))
    before = snapshot(out, state)
    res = pyoa([*PROGRESSIVE, "--size", "16", "16", "--out", out, "-q"], as_limit)
    refused(res, "render", r"cannot resume .*out\.exr\.state\.npz: its sum is float64 \(40000, 40000, 3\), not "
                           r"float64 \(16, 16, 3\); run without --resume to start over")
    assert snapshot(out, state) == before


def test_a_progressive_state_of_another_size_names_the_size(progressive_state, tmp_path, as_limit):
    """A larger state than this run's is named by its --size, not as an 'unexpected member' of so many bytes."""
    out, state = copy_progressive(progressive_state, tmp_path)
    before = snapshot(out, state)
    res = pyoa([*PROGRESSIVE, "--size", "8", "8", "--out", out, "-q"], as_limit)
    refused(res, "render", r"cannot resume .*: --size: it holds 16 x 16 pixels and this run asks for 8 x 8 \(--size, "
                           r"or the scene's film without it\); give --size 16 16 to continue it; run without --resume")
    assert snapshot(out, state) == before


def _as_renderer_1(state):
    """Rewrite a state's key as renderer version 1 wrote it (no ``renderer`` field)."""
    with np.load(state) as z:
        members = {k: z[k] for k in z.files}
    key = json.loads(str(members["key"][()]))
    assert key.pop("renderer") == RENDERER_VERSION
    members["key"] = np.array(json.dumps(key))
    with open(state, "wb") as fh:
        np.savez(fh, **members)


def test_work_of_another_renderer_version_is_not_mixed_in(progressive_state, tmp_path, as_limit):
    """Progressive and reference states made before the ray offsets changed
    (renderer version 1: no ``renderer`` in their key) are not resumed into
    this version's images: the progressive render refuses, naming the cause;
    the reference starts over; a study of version 1 is refused."""
    out, state = copy_progressive(progressive_state, tmp_path)
    _as_renderer_1(state)
    before = snapshot(out, state)
    res = pyoa([*PROGRESSIVE, "--size", "16", "16", "--out", out, "-q"], as_limit)
    refused(res, "render", r"cannot resume .*: it was made with another version of pyoa's renderer")
    assert snapshot(out, state) == before

    ref = tmp_path / "ref.exr"
    scene = load("cornell")
    p = plan(scene, sampler="sobol", spp=4, width=8, height=8, shading="numpy")
    key = reference_key(scene, p, pass_spp=4, passes=1, seed=0)
    Passes(state_path(ref), key, quiet=True).add(0, np.ones((8, 8, 3), np.float32))
    _as_renderer_1(state_path(ref))
    res = pyoa([*REFERENCE, "--size", "8", "8", "--out", ref, "-q"], as_limit)
    assert res.returncode == 0 and res.stderr.splitlines() == [
        f"pyoa reference: not resuming {state_path(ref)} (made with another version of pyoa's renderer (its images "
        "differ)): starting over"], res.stderr
    assert read_image(ref).mean() != 1.0

    from pyoa.study import check_settings

    settings = dict(version=1, renderer=RENDERER_VERSION, size=[8, 8], crop=[0, 0, 8, 8], max_depth=None,
                    filter="box", shading="numba", scenes={})
    saved = {k: v for k, v in settings.items() if k != "renderer"}
    with pytest.raises(ValueError, match=r"holds renders of pyoa's renderer version 1, and this pyoa renders with "
                                         rf"version {RENDERER_VERSION}"):
        check_settings(tmp_path, saved, settings)
    assert check_settings(tmp_path, dict(settings), settings)["renderer"] == RENDERER_VERSION


def test_a_forged_header_of_a_reference_state_starts_over(tmp_path, as_limit):
    """pyoa reference does not resume a state that holds no valid sums: it
    says why in one line and renders afresh, nothing allocated from the header."""
    out = tmp_path / "ref.exr"
    scene = load("cornell")
    p = plan(scene, sampler="sobol", spp=4, width=8, height=8, shading="numpy")
    key = reference_key(scene, p, pass_spp=4, passes=1, seed=0)
    Passes(state_path(out), key, quiet=True).add(0, np.ones((8, 8, 3), np.float32))  # a finished pass, saved
    forge(state_path(out), "sum.npy", (40000, 40000, 3))
    res = pyoa([*REFERENCE, "--size", "8", "8", "--out", out, "-q"], as_limit)
    assert res.returncode == 0 and "Traceback" not in res.stderr, res.stderr
    assert res.stderr.splitlines() == [f"pyoa reference: not resuming {state_path(out)} (its sum is float64 (40000, "
                                       "40000, 3), not float64 (8, 8, 3)): starting over"], res.stderr
    assert read_image(out).shape == (8, 8, 3) and not state_path(out).exists()


def test_a_header_claiming_more_than_its_member_holds_is_not_read(tmp_path, as_limit):
    """A reference state with 99 999 pending passes whose images (4.9 GB as
    the header says, of the expected shape) are 64 bytes: not resumed, and
    nothing larger than the member is allocated (a child under the memory cap)."""
    state = tmp_path / "ref.exr.state.npz"
    key = dict(width=64, height=64, passes=10**6)
    write_state(state, np.zeros((64, 64, 3)), "passes", 0, key, sumsq=np.zeros((64, 64, 3)),
                pending=np.arange(1, 10**5), images=np.zeros((0, 64, 64, 3), np.float32))
    forge(state, "images.npy", (10**5 - 1, 64, 64, 3), "<f4")
    res = python_child(f"""
        from pyoa.render.state import BadState, read_state_arrays
        try:
            read_state_arrays({str(state)!r}, {key!r}, "passes", 10**6, None, ("sum", "sumsq"), pending=True)
        except BadState as why:
            print(why)
    """, as_limit)
    assert res.returncode == 0 and res.stdout == ("its member images.npy is cut short: its header claims float32 "
                                                  "(99999, 64, 64, 3) (4915150848 bytes), it holds 64 bytes\n"), res


def test_a_compressed_member_is_not_inflated_beyond_its_stated_size(tmp_path, as_limit):
    """A state whose ``sum.npy`` is deflated zeros of 160 MiB (160 KiB in the
    file) with its zip header saying 1.5 MiB, what a 256 x 256 sum holds: refused, and nothing near the
    inflated size is allocated (a child under the memory cap; ``zf.read``
    used to inflate the member whole before its CRC check failed)."""
    import struct
    import zipfile

    state = tmp_path / "ref.exr.state.npz"
    key = dict(width=256, height=256, passes=8)
    write_state(state, np.zeros((256, 256, 3)), "passes", 0, key, sumsq=np.zeros((256, 256, 3)),
                pending=np.zeros(0, np.int64), images=np.zeros((0, 256, 256, 3), np.float32))
    members = {}
    with zipfile.ZipFile(state) as zf:
        for info in zf.infolist():
            members[info.filename] = zf.read(info)
    header = members["sum.npy"][:128]  # the .npy header of a (256, 256, 3) float64 array
    with zipfile.ZipFile(state, "w") as zf:
        for name, data in members.items():
            if name == "sum.npy":
                zf.writestr(name, header + bytes(160 << 20), compress_type=zipfile.ZIP_DEFLATED)
            else:
                zf.writestr(name, data)
    raw = bytearray(state.read_bytes())
    stated = len(members["sum.npy"])
    for sig, at in ((b"PK\x03\x04", 22), (b"PK\x01\x02", 24)):  # local and central headers: uncompressed size
        k = -1
        while (k := raw.find(sig, k + 1)) >= 0:
            name_len = struct.unpack_from("<H", raw, k + (26 if sig == b"PK\x03\x04" else 28))[0]
            name_at = k + (30 if sig == b"PK\x03\x04" else 46)
            if raw[name_at:name_at + name_len] == b"sum.npy":
                struct.pack_into("<I", raw, k + at, stated)
    state.write_bytes(bytes(raw))
    assert state.stat().st_size < 4 << 20
    res = python_child(f"""
        from pyoa.render.state import BadState, read_state_arrays

        def peak():
            return next(int(l.split()[1]) for l in open("/proc/self/status") if l.startswith("VmHWM")) << 10

        before = peak()
        try:
            read_state_arrays({str(state)!r}, {key!r}, "passes", 8, None, ("sum", "sumsq"), pending=True)
        except BadState as why:
            print(why)
        print((peak() - before) >> 20)
    """, as_limit)
    # refused either way: it inflates to more than its header says, or its CRC fails at that size;
    # what matters is that it is never inflated whole (160 MiB): a few MiB at most
    why, grown = res.stdout.splitlines()
    assert res.returncode == 0 and "sum.npy" in why and int(grown) < 48, res


# -- the scene in the memory plan (item 14) -------------------------------------------------------


def grid_ply(path, n: int) -> int:
    """A binary PLY of an n x n grid of squares (2 n^2 triangles) in [-0.5, 0.5]^2; returns the triangle count."""
    u = np.linspace(-0.5, 0.5, n + 1, dtype="<f4")
    x, y = np.meshgrid(u, u)
    vertices = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size, "<f4")])
    i = (np.arange(n)[:, None] * (n + 1) + np.arange(n)).ravel()
    faces = np.empty(2 * len(i), dtype=[("n", "u1"), ("v", "<i4", 3)])
    faces["n"] = 3
    faces["v"][0::2] = np.column_stack([i, i + 1, i + n + 2])
    faces["v"][1::2] = np.column_stack([i, i + n + 2, i + n + 1])
    header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(vertices)}\nproperty float x\n"
              f"property float y\nproperty float z\nelement face {len(faces)}\n"
              "property list uchar int vertex_indices\nend_header\n")
    path.write_bytes(header.encode() + vertices.tobytes() + faces.tobytes())
    return len(faces)


def scene_with_mesh(directory, n: int):
    """cornell with an n x n grid mesh in it: (scene path, mesh triangles)."""
    data = json.loads(open(bundled()["cornell"]).read())
    data["shapes"].append({"type": "mesh", "file": f"grid{n}.ply", "material": "white",
                           "to_world": [[0.5, 0, 0, 0], [0, 0.5, 0, 0], [0, 0, 0.5, 0], [0, 0, 0, 1]]})
    path = directory / f"grid{n}.json"
    path.write_text(json.dumps(data))
    return path, grid_ply(directory / f"grid{n}.ply", n)


def test_a_mesh_over_the_memory_limit_is_refused_before_loading(tmp_path, as_limit):
    """A mesh of 40 328 triangles (a 0.7 MB PLY) needs about 39 MiB to load: refused under a limit of 16 MiB."""
    scene, triangles = scene_with_mesh(tmp_path, 142)
    out = tmp_path / "x.exr"
    res = pyoa(["render", scene, "--size", "8", "8", "--spp", "1", "--sampler", "sobol", *FAST, "--out", out, "-q"],
               as_limit, env={"PYOA_MAX_BYTES": "16M"})
    need = re.escape(format_bytes(triangles * MESH_TRIANGLE_BYTES))
    refused(res, "render", rf"grid142\.json: shapes\[8\]\.file: loading mesh 'grid142\.ply' of {triangles} triangles "
                           rf"needs {need}, over the memory limit of 16\.0 MiB; use a mesh of fewer triangles, or "
                           r"raise the limit with max_bytes= or \$PYOA_MAX_BYTES")
    assert not out.exists()


def test_a_mesh_file_too_large_to_parse_is_refused_before_parsing(tmp_path, monkeypatch):
    import trimesh

    path, _ = scene_with_mesh(tmp_path, 64)
    size = (tmp_path / "grid64.ply").stat().st_size
    monkeypatch.setattr(trimesh, "load", lambda *a, **k: pytest.fail("the mesh was parsed"))
    need = re.escape(format_bytes(size * MESH_FILE_FACTOR))
    with pytest.raises(SceneError, match=rf"grid64\.json: shapes\[8\]\.file: parsing mesh 'grid64\.ply' \({size} "
                                         rf"bytes\) needs {need}, over the memory limit of 1\.0 MiB"):
        load(path, max_bytes="1M")


def test_the_render_plan_counts_the_scene(tmp_path):
    """A scene loaded under a larger limit is refused by a render under a smaller one, before Embree builds."""
    path, _ = scene_with_mesh(tmp_path, 64)
    scene = load(path)
    traced = re.escape(format_bytes(len(scene.triangles) * SCENE_TRIANGLE_BYTES))
    with pytest.raises(ValueError, match=r"a 8 x 8 render at 1 spp \(18 dims\) needs \d\.\d MiB, over the memory limit "
                                         rf"of 2\.0 MiB; render a scene of fewer triangles \(its "
                                         rf"{len(scene.triangles)} triangles take {traced} to trace\)"):
        render(scene, sampler="sobol", spp=1, width=8, height=8, max_bytes="2M")


def test_meshes_loaded_before_count_what_they_keep(tmp_path):
    """Four meshes of 2048 triangles load under a limit of the last one at
    MESH_TRIANGLE_BYTES plus the three before it at MESH_KEPT_BYTES (their
    arrays, not a parse: only one mesh is parsed at a time), though all four
    at 1 KiB need more; one byte less is refused, naming both counts. Every
    triangle loaded so far used to count 1 KiB: ten 1M-triangle meshes were
    refused under the default limit of a 16 GB machine (8 GiB)."""
    triangles = grid_ply(tmp_path / "grid32.ply", 32)
    data = json.loads(open(bundled()["cornell"]).read())
    for k in range(4):
        data["shapes"].append({"type": "mesh", "file": "grid32.ply", "material": "white",
                               "to_world": [[0.5, 0, 0, 0], [0, 0.5, 0, 0], [0, 0, 0.5, 0.1 * k], [0, 0, 0, 1]]})
    path = tmp_path / "meshes.json"
    path.write_text(json.dumps(data))
    plan = triangles * MESH_TRIANGLE_BYTES + 3 * triangles * MESH_KEPT_BYTES
    assert 4 * triangles * MESH_TRIANGLE_BYTES > plan
    assert len(load(path, max_bytes=plan).triangles) == len(load("cornell").triangles) + 4 * triangles
    need, limit = (re.escape(format_bytes(b)) for b in (plan, plan - 1))
    with pytest.raises(SceneError, match=rf"meshes\.json: shapes\[11\]\.file: loading mesh 'grid32\.ply' of "
                                         rf"{triangles} triangles \(and the {3 * triangles} triangles of the meshes "
                                         rf"before it\) needs {need}, over the memory limit of {limit}"):
        load(path, max_bytes=plan - 1)


def test_running_out_of_memory_is_one_line(tmp_path):
    """$PYOA_MAX_BYTES above what the process may use (RLIMIT_AS 256 MiB
    above its size once the renderer's modules are loaded): the MemoryError
    of a 20000 x 20000 image (4.5 GiB) is a one-line error."""
    out = tmp_path / "x.exr"
    argv = ["render", "cornell", "--size", "20000", "20000", "--spp", "1", "--sampler", "sobol", *FAST, "--out",
            str(out), "-q"]
    code = f"""
        import resource
        import embreex
        import pyoa.commands.render, pyoa.render.integrator
        from pyoa.commands import main
        from pyoa.render.image import check_output
        check_output({str(out)!r}, "--out", (".exr",))  # loads OpenImageIO's EXR writer
        size = int(next(l for l in open("/proc/self/status") if l.startswith("VmSize")).split()[1]) * 1024
        resource.setrlimit(resource.RLIMIT_AS, (size + (256 << 20),) * 2)
        main({argv!r})
    """
    res = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True,
                         timeout=TIMEOUT, env={**os.environ, "PYOA_MAX_BYTES": "1T"})
    refused(res, "render", r"out of memory \(Unable to allocate .*\): this job needs more memory than the process may "
                           r"use; render a smaller scene, image or sample count, or set \$PYOA_MAX_BYTES")
    assert not out.exists()


# -- Ctrl-C (item 14) ---------------------------------------------------------------------------------


def interrupt(argv, limit, started):
    """Start ``pyoa argv``, send it SIGINT once ``started()`` is true (its
    work is under way), and return (exit status, stderr)."""
    child = pyoa(argv, limit, popen=True)
    try:
        deadline = time.monotonic() + TIMEOUT
        while not started() and child.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)
        child.send_signal(signal.SIGINT)
        _, err = child.communicate(timeout=TIMEOUT)
    finally:
        child.kill()
    return child.returncode, err


def test_ctrl_c_on_a_progressive_render_keeps_the_last_doubling(tmp_path, as_limit):
    out = tmp_path / "p.exr"
    code, err = interrupt(["render", "cornell", "--size", "32", "32", "--sampler", "sobol", "--spp", "65536",
                           "--progressive", *FAST, "--out", out, "-q"], as_limit, state_path(out).exists)
    assert code == 130, (code, err)
    assert err.splitlines() == [f"pyoa render: interrupted; {out} and {state_path(out)} hold the last complete "
                                "doubling (continue with --resume)"], err
    with np.load(state_path(out)) as st:  # the image is the state's mean: a complete doubling, not a part
        done = int(st["samples"])
        np.testing.assert_array_equal(read_image(out), (st["sum"] / done).astype(np.float32))
    assert done >= 1 and done & (done - 1) == 0
    assert sorted(os.listdir(tmp_path)) == ["p.exr", "p.exr.state.npz"]  # no temporary file left


def test_ctrl_c_on_a_study_keeps_its_rows(tmp_path, as_limit):
    ref = tmp_path / "ref.exr"
    write_exr(ref, np.full((8, 8, 3), 0.5, np.float32))
    out = tmp_path / "study"

    def rows():
        return (out / "study.csv").read_text().count("\n") - 1 if (out / "study.csv").exists() else 0

    code, err = interrupt(["study", "cornell", "--samplers", "sobol", "--spp", "64", "--seeds", "4096", "--size",
                           "8", "8", "--reference", ref, *FAST, "--out", out, "-q"], as_limit, lambda: rows() >= 1)
    assert code == 130, (code, err)
    assert err.splitlines() == [f"pyoa study: interrupted; the finished renders are kept in {out} (run the same "
                                "command again to continue)"], err
    text = (out / "study.csv").read_text()
    assert rows() >= 1 and text.endswith("\n")  # whole rows only
