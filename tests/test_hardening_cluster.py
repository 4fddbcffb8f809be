"""Hardening of the cluster engine (issue 33, items 11 and 12): a bad
``--scheduler`` or ``$PYOA_SCHEDULER`` is refused in one line before anything
is connected to, a port where no Dask scheduler listens is refused within
the stated time and without ``Client.__del__``'s traceback, and a mesh whose
data lives in other files (a glTF's ``.bin`` buffers) renders on workers
that only have what the client sent them. Everything runs for real: the
commands in subprocesses, the renders on a ``distributed.LocalCluster`` of
worker processes."""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

from pyoa import cluster
from pyoa.render.render import render
from pyoa.render.scene import bundled, load
from pyoa.render.scene_source import source_of
from pyoa.render.tiles import render_on

distributed = pytest.importorskip("distributed")

OLD = b"previous output"

#: CONNECT_TIMEOUT of the child that connects to a port where no Dask
#: scheduler listens (10 s by default: too long for the suite).
TIMEOUT = 2

#: Runs ``pyoa.commands.main`` with ``cluster.CONNECT_TIMEOUT = TIMEOUT``, as ``python -m pyoa`` runs it.
MAIN = ("import sys, pyoa.cluster; pyoa.cluster.CONNECT_TIMEOUT = %d; from pyoa.commands import main; "
        "sys.exit(main(sys.argv[1:]))" % TIMEOUT)

#: case -> (--scheduler value or None, $PYOA_SCHEDULER or None, words of the message)
BAD_SCHEDULERS = {
    "garbage": ("garbage", None, ["--scheduler 'garbage' has no port", "tcp://garbage:8786"]),
    "no-host": ("tcp://", None, ["--scheduler 'tcp://' has no host", "SCHEME://HOST:PORT"]),
    "udp": ("udp://10.0.0.5:8786", None, ["has an unknown scheme 'udp'", "tcp, tls"]),
    "bare-host": ("127.0.0.1", None, ["--scheduler '127.0.0.1' has no port", "tcp://127.0.0.1:8786"]),
    "env-garbage": (None, "garbage", ["$PYOA_SCHEDULER 'garbage' has no port", "tcp://garbage:8786"]),
}


@pytest.fixture(scope="module")
def listener():
    """A plain TCP socket listening on a free port that never answers (the
    kernel accepts connections into its backlog): not a Dask scheduler."""
    with socket.socket() as srv:
        srv.bind(("127.0.0.1", 0))
        srv.listen(16)
        yield f"tcp://127.0.0.1:{srv.getsockname()[1]}"


class Run:
    """A command started now, in the background; a thread collects its
    output and the time it exited (while the tests do other things)."""

    def __init__(self, argv: list[str], env: dict, out):
        self.out, self.mtime = out, out.stat().st_mtime_ns
        self.t0 = time.perf_counter()
        self.proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
        self.thread = threading.Thread(target=self._collect, daemon=True)
        self.thread.start()

    def _collect(self):
        self.stdout, self.stderr = self.proc.communicate()
        self.took = time.perf_counter() - self.t0

    def finished(self, limit: float = 60) -> tuple[int, str, str, float]:
        """Exit status, stdout, stderr and seconds from start to exit, once
        exited; the output file it was given must be as it was."""
        self.thread.join(max(0.0, self.t0 + limit - time.perf_counter()))
        if self.thread.is_alive():
            self.proc.kill()
            pytest.fail(f"{self.proc.args}: still running after {limit} s")
        assert self.out.read_bytes() == OLD and self.out.stat().st_mtime_ns == self.mtime  # not touched
        return self.proc.returncode, self.stdout, self.stderr, self.took


@pytest.fixture(scope="module")
def runs(tmp_path_factory, listener):
    """Every refused command started at once (each waits on nothing but
    itself and the listener): case -> :class:`Run`."""
    started = {}
    cases = {**BAD_SCHEDULERS, "not-dask": (listener, None, [])}
    for case, (flag, env_value, _words) in cases.items():
        out = tmp_path_factory.mktemp(case) / "old.exr"
        out.write_bytes(OLD)
        env = {k: v for k, v in os.environ.items() if k != cluster.ENV_SCHEDULER}
        if env_value is not None:
            env[cluster.ENV_SCHEDULER] = env_value
        argv = ["render", "cornell", "--size", "4", "4", "--spp", "4", "--out", str(out), "-q"]
        argv += ["--scheduler", flag] if flag is not None else []
        head = [sys.executable, "-c", MAIN] if case == "not-dask" else [sys.executable, "-m", "pyoa"]
        started[case] = Run(head + argv, env, out)
    yield started
    for run in started.values():
        if run.proc.poll() is None:
            run.proc.kill()


def refused(code: int, stdout: str, stderr: str) -> str:
    """Exit status 2, nothing on stdout and one line ``pyoa render: error: ...`` on stderr."""
    assert code == 2, (code, stdout, stderr)
    lines = stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("pyoa render: error: "), stderr
    assert "Traceback" not in stderr and stdout == ""
    return lines[0]


# -- item 11: the files a mesh reads are sent to the workers ---------------------------------------


@pytest.fixture(scope="module")
def scheduler(tmp_path_factory, runs):
    """A LocalCluster of 1 worker process (1 thread) whose temporary directory,
    where it writes the scene files it is sent, is new and its own. (Asks for
    ``runs`` so that the refused commands run while it starts.)"""
    worker_tmp = tmp_path_factory.mktemp("worker-tmp")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=40, env={"TMPDIR": str(worker_tmp)}) as lc:
        yield lc.scheduler_address, worker_tmp


def gltf_scene(root) -> str:
    """cornell with a box mesh written by trimesh as ``meshes/box.gltf`` and
    its separate ``.bin`` buffers; the scene file in a sibling folder."""
    import trimesh

    (root / "meshes").mkdir()
    trimesh.creation.box(extents=(0.4, 0.6, 0.4)).export(str(root / "meshes" / "box.gltf"))
    assert any(p.suffix == ".bin" for p in (root / "meshes").iterdir())  # the data is not in the .gltf
    data = json.loads(open(bundled()["cornell"]).read())
    data["shapes"].append({"type": "mesh", "file": "../meshes/box.gltf", "material": data["shapes"][0]["material"],
                           "to_world": [[1, 0, 0, 0.2], [0, 1, 0, -0.7], [0, 0, 1, 0.1], [0, 0, 0, 1]]})
    (root / "scenes").mkdir()
    path = root / "scenes" / "room.json"
    path.write_text(json.dumps(data))
    return str(path)


def _loaded_paths():
    from pyoa.render import scene_source

    return [s.path for s in scene_source._LOADED.values()]


def test_a_gltf_with_separate_buffers_renders_on_the_workers(tmp_path, scheduler):
    address, worker_tmp = scheduler
    sc = load(gltf_scene(tmp_path))
    bins = sorted(f"meshes/{p.name}" for p in (tmp_path / "meshes").iterdir() if p.suffix == ".bin")
    assert sorted(rel for rel, _ in source_of(sc).files) == sorted(["meshes/box.gltf", "scenes/room.json", *bins])
    kw = dict(sampler="bose", spp=4, seed=2, width=8, height=8)
    want = render(sc, **kw).image
    with cluster.engine(scheduler=address) as eng:
        got = render_on(eng, sc, **kw).image  # once: the worker could not load the mesh without its buffers
        paths = [p for ps in eng.client.run(_loaded_paths).values() for p in ps]
    assert np.array_equal(got.view(np.uint32), want.view(np.uint32))
    # the worker loaded the copy it was sent, in its own temporary directory
    assert paths and all(p.startswith(str(worker_tmp)) for p in paths), paths


#: A tetrahedron whose faces use the material of its library.
OBJ = "mtllib pyramid.mtl\nusemtl grey\nv 0 0 0\nv 1 0 0\nv 0 0 1\nv 0 1 0\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n"


def test_an_obj_material_library_is_sent_with_the_mesh(tmp_path):
    (tmp_path / "pyramid.mtl").write_text("newmtl grey\nKd 0.5 0.5 0.5\n")
    (tmp_path / "pyramid.obj").write_text(OBJ)
    data = json.loads(open(bundled()["cornell"]).read())
    data["shapes"].append({"type": "mesh", "file": "pyramid.obj", "material": data["shapes"][0]["material"],
                           "to_world": [[0.5, 0, 0, -0.2], [0, 0.5, 0, -1], [0, 0, 0.5, 0.3], [0, 0, 0, 1]]})
    (tmp_path / "room.json").write_text(json.dumps(data))
    src = source_of(load(str(tmp_path / "room.json")))
    assert sorted(rel for rel, _ in src.files) == ["pyramid.mtl", "pyramid.obj", "room.json"]


# -- item 12: scheduler addresses (the commands ran while the cluster above started) ----------------


@pytest.mark.parametrize("case", list(BAD_SCHEDULERS))
def test_a_bad_scheduler_address_is_refused_before_connecting(runs, case):
    code, stdout, stderr, took = runs[case].finished()
    line = refused(code, stdout, stderr)
    for w in BAD_SCHEDULERS[case][2]:
        assert w in line, line
    assert "within" not in line  # it waited for nothing (once: "within 10 s", then 20 s and a traceback)
    assert took < 10, took


def test_a_port_that_is_not_a_dask_scheduler_is_refused_in_the_stated_time(runs, listener):
    code, stdout, stderr, took = runs["not-dask"].finished()
    line = refused(code, stdout, stderr)
    waited = TIMEOUT + cluster.HANDSHAKE_GRACE
    assert f"no Dask scheduler answered at {listener!r} within {waited:g} s" in line, line
    assert "did not answer as a Dask scheduler does" in line, line
    # the stated wait, plus starting Python and importing pyoa (about 2 s, more while the other cases start):
    # once 58 s at a 10 s timeout
    assert waited <= took < waited + 8, took
