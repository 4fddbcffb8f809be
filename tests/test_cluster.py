"""Renders, references and studies on a real Dask cluster (a LocalCluster of
two worker processes, never a mock): the same bits as in-process, resumable,
surviving a killed worker, and refusing bad input before any task runs."""

from __future__ import annotations

import csv
import os
import signal
import socket
import subprocess
import sys
import time

import numpy as np
import pytest

from pyoa import cluster
from pyoa.commands import main
from pyoa.render import reference as reference_mod
from pyoa.render.image import read_image
from pyoa.render.render import render
from pyoa.render.scene import load
from pyoa.render.tiles import render_on, tile_ranges

distributed = pytest.importorskip("distributed")


@pytest.fixture(scope="module")
def scheduler():
    """The address of a LocalCluster of 2 worker processes (1 thread each)."""
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=40) as lc:
        yield lc.scheduler_address


def bits(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float32).view(np.uint32)


def rows_of(path) -> dict:
    """study.csv as {(scene, sampler, spp asked, seed): (spp, relmse, relmse_crop, mse)}."""
    with open(path) as fh:
        return {(r["scene"], r["sampler"], r["spp_asked"], r["seed"]): (r["spp"], r["relmse"], r["relmse_crop"],
                                                                        r["mse"]) for r in csv.DictReader(fh)}


# -- the engine ------------------------------------------------------------------------------------


def test_in_process_is_the_default(monkeypatch):
    monkeypatch.delenv(cluster.ENV_SCHEDULER, raising=False)
    with cluster.engine() as eng:
        assert eng.client is None and eng.description == "in-process"
        assert list(eng.run(divmod, [(7, 2), (9, 4)])) == [(0, (3, 1)), (1, (2, 1))]


@pytest.mark.parametrize("workers, scheduler, match", [
    (0, None, r"--workers must be in \[1, 1024\]"),
    (2, "tcp://127.0.0.1:1", "not both"),
    (None, "  ", "scheduler address such as tcp://"),
])
def test_engine_arguments_are_checked(workers, scheduler, match):
    with pytest.raises(ValueError, match=match):
        with cluster.engine(workers, scheduler):
            pass


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_a_silent_scheduler_fails_fast_with_a_clear_message(capsys, monkeypatch):
    address = f"tcp://127.0.0.1:{_free_port()}"
    monkeypatch.setattr(cluster, "CONNECT_TIMEOUT", 3)
    t0 = time.perf_counter()
    with pytest.raises(SystemExit) as exc:
        main(["render", "cornell", "--size", "4", "4", "--spp", "4", "--out", "unused.exr", "--scheduler", address,
              "-q"])
    took = time.perf_counter() - t0
    err = capsys.readouterr().err
    assert exc.value.code == 2
    # nothing listens on the port: the refused connection is final, not waited on for CONNECT_TIMEOUT
    assert f"no Dask scheduler answered at {address!r}: connection refused" in err and "dask scheduler" in err, err
    assert took < 15, took
    assert not os.path.exists("unused.exr")


def test_the_environment_names_the_scheduler(monkeypatch, capsys):
    address = f"tcp://127.0.0.1:{_free_port()}"
    monkeypatch.setenv(cluster.ENV_SCHEDULER, address)
    monkeypatch.setattr(cluster, "CONNECT_TIMEOUT", 2)
    with pytest.raises(cluster.ClusterUnavailable, match="PYOA_SCHEDULER"):
        with cluster.engine():
            pass


def test_tiles_cover_the_image_once():
    for n, spp, slots in [(1, 1, 1), (7, 4, 3), (4096, 16, 2), (100, 1 << 20, 8)]:
        tiles = tile_ranges(n, spp, slots)
        assert [p for t in tiles for p in t] == list(range(n))


# -- renders -------------------------------------------------------------------------------------


@pytest.mark.parametrize("scene, sampler, spp", [("cornell", "bose", 16), ("dof7d", "sobol", 32),
                                                 ("dof7d", "zsobol", 16)])
def test_a_render_on_the_cluster_is_bit_identical(scheduler, scene, sampler, spp):
    sc = load(scene)
    kw = dict(sampler=sampler, spp=spp, seed=5, width=19, height=13)
    want = render(sc, **kw)
    with cluster.engine(scheduler=scheduler) as eng:
        got = render_on(eng, sc, **kw)
    np.testing.assert_array_equal(bits(got.image), bits(want.image))
    assert got.stats.paths == want.stats.paths == 19 * 13 * spp


def test_pixel_tiles_are_the_full_render(tmp_path):
    """Any split of the pixels gives each pixel the full render's bits."""
    sc = load("dof7d")
    kw = dict(sampler="bose", spp=25, seed=1, width=11, height=7)
    full = render(sc, **kw).image.reshape(-1, 3)
    for cut in ([0, 77], [0, 3, 40, 41, 77], [0, 1, 76, 77]):
        parts = [render(sc, **kw, pixels=range(a, b), batch_paths=50).image for a, b in zip(cut, cut[1:])]
        np.testing.assert_array_equal(bits(np.concatenate(parts)), bits(full))


def test_render_and_compare_commands_on_the_cluster(tmp_path, scheduler):
    a, b = tmp_path / "a.exr", tmp_path / "b.exr"
    argv = ["render", "dof7d", "--size", "16", "12", "--spp", "16", "--seed", "3", "-q"]
    assert main([*argv, "--out", str(a)]) == 0
    assert main([*argv, "--out", str(b), "--scheduler", scheduler]) == 0
    np.testing.assert_array_equal(bits(read_image(a)), bits(read_image(b)))
    rows = []
    for where in ([], ["--scheduler", scheduler]):
        stem = tmp_path / f"cmp{len(rows)}"
        assert main(["compare", "dof7d", "--size", "16", "12", "--spp", "16", "--samplers", "random,bose",
                     "--reference", str(a), "--out", str(stem), "-q", *where]) == 0
        with open(f"{stem}.csv") as fh:
            rows.append([(r["sampler"], r["relmse"], r["relmse_crop"]) for r in csv.DictReader(fh)])
    assert rows[0] == rows[1]


# -- references ------------------------------------------------------------------------------------

REF = ["cornell", "--size", "10", "8", "--spp", "48", "--pass-spp", "8", "-q"]


def test_an_interrupted_reference_resumes_on_the_cluster(tmp_path, scheduler, monkeypatch):
    """Killed after 3 of 6 passes arrived (in any order), resumed on the
    cluster: only the missing passes are rendered, and the image and its
    variance are the uninterrupted in-process ones, bit for bit."""
    full = tmp_path / "full.exr"
    assert main(["reference", *REF, "--out", str(full)]) == 0
    out = tmp_path / "ref.exr"
    real_add = reference_mod.Passes.add
    seen = []

    def add(self, k, image):
        real_add(self, k, image)
        seen.append(k)
        if len(seen) == 3:
            raise KeyboardInterrupt

    monkeypatch.setattr(reference_mod.Passes, "add", add)
    with pytest.raises(SystemExit, match="^130$"):  # pyoa.commands: Ctrl-C is exit status 130
        main(["reference", *REF, "--out", str(out), "--scheduler", scheduler])
    monkeypatch.setattr(reference_mod.Passes, "add", real_add)
    state = reference_mod.state_path(out)
    assert state.exists()
    submitted = []
    real_run = cluster.DaskEngine.run

    def run(self, fn, args, **kw):
        submitted.append(sorted(a[3] for a in args))
        return real_run(self, fn, args, **kw)

    monkeypatch.setattr(cluster.DaskEngine, "run", run)
    assert main(["reference", *REF, "--out", str(out), "--scheduler", scheduler]) == 0
    assert submitted == [sorted(set(range(6)) - set(seen))]
    np.testing.assert_array_equal(bits(read_image(out)), bits(read_image(full)))
    np.testing.assert_array_equal(bits(read_image(reference_mod.variance_path(out))),
                                  bits(read_image(reference_mod.variance_path(full))))
    assert not state.exists()


def test_passes_join_the_sums_in_order_whatever_order_they_arrive(tmp_path):
    key = dict(height=2, width=3, passes=4)
    rng = np.random.default_rng(1)
    images = [rng.random((2, 3, 3), dtype=np.float32) * 10 for _ in range(4)]
    a = reference_mod.Passes(tmp_path / "a.npz", key, quiet=True)
    for k in range(4):
        a.add(k, images[k])
    b = reference_mod.Passes(tmp_path / "b.npz", key, quiet=True)
    for k in (2, 0, 3):
        b.add(k, images[k])
    assert b.done == 1 and sorted(b.pending) == [2, 3]
    b = reference_mod.Passes(tmp_path / "b.npz", key, quiet=True)  # resumed from its state
    assert b.done == 1 and sorted(b.pending) == [2, 3] and b.todo == [1]
    b.add(1, images[1])
    np.testing.assert_array_equal(bits(a.mean()), bits(b.mean()))
    np.testing.assert_array_equal(a.variance(), b.variance())


# -- studies -------------------------------------------------------------------------------------

STUDY = ["dof7d", "--samplers", "random,bose", "--spp", "16,49", "--seeds", "4", "--size", "12", "12",
         "--reference-spp", "1024", "-q"]


@pytest.fixture(scope="module")
def inprocess_study(tmp_path_factory):
    out = tmp_path_factory.mktemp("study") / "in"
    assert main(["study", *STUDY, "--out", str(out)]) == 0
    return out


def test_a_study_has_every_row_and_intervals(inprocess_study):
    rows = rows_of(inprocess_study / "study.csv")
    assert len(rows) == 2 * 2 * 4
    from pyoa.study import cells, read_rows

    table = cells(read_rows(inprocess_study / "study.csv"), {})
    for by_spp in table["dof7d"].values():
        for c in by_spp.values():
            m, lo, hi = c.ci()
            assert lo < m < hi and c.seeds == 4
    means = {n: np.mean([c.values.mean() for c in by.values()]) for n, by in table["dof7d"].items()}
    assert means["random"] > means["bose"], means
    md = (inprocess_study / "study.md").read_text()
    assert "## dof7d" in md and "its own noise adds an estimated" in md and "| bose |" in md
    assert (inprocess_study / "study.png").stat().st_size > 0 and (inprocess_study / "study-dof7d.png").exists()


def test_a_study_on_the_cluster_has_the_same_rows(inprocess_study, tmp_path, scheduler):
    out = tmp_path / "cl"
    assert main(["study", *STUDY, "--out", str(out), "--scheduler", scheduler]) == 0
    assert rows_of(out / "study.csv") == rows_of(inprocess_study / "study.csv")
    np.testing.assert_array_equal(bits(read_image(out / "reference-dof7d.exr")),
                                  bits(read_image(inprocess_study / "reference-dof7d.exr")))


def test_an_interrupted_study_resumes_and_renders_only_what_is_missing(inprocess_study, tmp_path, monkeypatch):
    from pyoa import study

    out = tmp_path / "st"
    real = study.RowWriter.add
    n = []

    def add(self, row):
        real(self, row)
        n.append(row)
        if len(n) == 5:
            self.fh.write("dof7d,bose,16,16,3,0.01")  # a row cut short by the kill
            self.fh.flush()
            raise KeyboardInterrupt

    monkeypatch.setattr(study.RowWriter, "add", add)
    with pytest.raises(SystemExit, match="^130$"):  # pyoa.commands: Ctrl-C is exit status 130
        main(["study", *STUDY, "--out", str(out)])
    monkeypatch.setattr(study.RowWriter, "add", real)
    rendered = []
    real_task = study.study_task

    def task(*a):
        rendered.append(a[4].ident)
        return real_task(*a)

    monkeypatch.setattr(study, "study_task", task)
    assert main(["study", *STUDY, "--out", str(out)]) == 0
    assert len(rendered) == 16 - 5
    assert rows_of(out / "study.csv") == rows_of(inprocess_study / "study.csv")
    # a run with nothing left renders nothing, and study.json keeps every finished run's time
    rendered.clear()
    assert main(["study", *STUDY, "--out", str(out)]) == 0
    import json

    runs = json.loads((out / "study.json").read_text())["runs"]
    assert rendered == [] and [r["rendered"] for r in runs] == [11, 0]
    assert "in all (2 runs" in (out / "study.md").read_text()


def test_a_killed_worker_costs_only_its_task(inprocess_study, tmp_path):
    """A worker process killed (SIGKILL) while the study runs: its task runs
    again elsewhere, and the rows are the in-process study's."""
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=50) as lc, distributed.Client(lc) as client:
        pids = list(client.run(os.getpid).values())
        out = tmp_path / "killed"
        argv = [*STUDY, "--out", str(out), "--scheduler", lc.scheduler_address]
        # the references are rendered first (so the kill lands during the study's renders)
        proc = subprocess.Popen([sys.executable, "-m", "pyoa", "study", *argv], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
        csv_path = out / "study.csv"
        deadline = time.time() + 120
        while time.time() < deadline and proc.poll() is None:
            if csv_path.exists() and len(csv_path.read_text().splitlines()) >= 3:
                break
            time.sleep(0.05)
        os.kill(pids[0], signal.SIGKILL)
        _, err = proc.communicate(timeout=300)
        assert proc.returncode == 0, err
    assert rows_of(out / "study.csv") == rows_of(inprocess_study / "study.csv")


def test_a_study_of_other_settings_is_refused(inprocess_study, tmp_path, capsys):
    import shutil

    out = tmp_path / "copy"
    shutil.copytree(inprocess_study, out)
    argv = [a if a != "12" else "10" for a in STUDY]  # --size 10 10
    with pytest.raises(SystemExit) as exc:
        main(["study", *argv, "--out", str(out)])
    assert exc.value.code == 2
    assert "holds a study made with size [12, 12], not [10, 10]; give another --out" in capsys.readouterr().err


@pytest.mark.parametrize("argv, match", [
    (["--out", "{tmp}/missing/dir"], "its parent directory"),
    (["--out", "{tmp}/file.txt"], "is a file"),
    (["--reference", "{tmp}/nope.exr", "--out", "{tmp}/o"], "no such image"),
    (["--reference-spp", "1000", "--pass-spp", "256", "--out", "{tmp}/o"], "must be a multiple of --pass-spp"),
    (["--reference-spp", "256", "--samplers", "bose,nope", "--out", "{tmp}/o"], "nope"),
    (["--reference-spp", "256", "--crop", "0", "0", "40", "40", "--out", "{tmp}/o"], "does not fit"),
])
def test_bad_study_input_fails_before_any_task(tmp_path, capsys, monkeypatch, scheduler, argv, match):
    (tmp_path / "file.txt").write_text("x")

    def no_tasks(*a, **k):
        raise AssertionError("a task was submitted")

    monkeypatch.setattr(cluster.DaskEngine, "run", no_tasks)
    monkeypatch.setattr(cluster.InProcess, "run", no_tasks)
    argv = [a.format(tmp=tmp_path) for a in argv]
    if "--reference" not in argv and "--reference-spp" not in argv:
        argv += ["--reference-spp", "256"]
    with pytest.raises(SystemExit) as exc:
        main(["study", "dof7d", "--size", "12", "12", "--spp", "16", "--seeds", "2", *argv, "--scheduler",
              scheduler, "-q"])
    assert exc.value.code == 2
    assert match in capsys.readouterr().err


@pytest.mark.parametrize("command, extra, match", [
    ("render", ["--out", "{tmp}/missing/x.exr"], "missing"),
    ("render", ["--out", "{tmp}/x.png"], "must end in .exr"),
    ("reference", ["--pass-spp", "8", "--out", "{tmp}/missing/x.exr"], "missing"),
    ("compare", ["--reference", "{tmp}/nope.exr", "--out", "{tmp}/c"], "no such image"),
])
def test_bad_output_or_reference_fails_before_any_task(tmp_path, capsys, monkeypatch, scheduler, command, extra,
                                                       match):
    def no_tasks(*a, **k):
        raise AssertionError("a task was submitted")

    monkeypatch.setattr(cluster.DaskEngine, "run", no_tasks)
    extra = [a.format(tmp=tmp_path) for a in extra]
    with pytest.raises(SystemExit) as exc:
        main([command, "cornell", "--size", "8", "8", "--spp", "16", *extra, "--scheduler", scheduler, "-q"])
    assert exc.value.code == 2
    assert match in capsys.readouterr().err


def test_a_scene_file_with_a_mesh_is_sent_to_the_workers(tmp_path, scheduler):
    """A scene outside the package, with a mesh in a sibling folder: the
    workers load it from the bytes the client sends (no shared files), and
    render the in-process image."""
    import json

    from pyoa.render.scene import bundled
    from pyoa.render.scene_source import source_of

    from .render.test_scene import OBJ

    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "pyramid.obj").write_text(OBJ)
    (tmp_path / "scenes").mkdir()
    data = json.loads(open(bundled()["cornell"]).read())
    data["shapes"].append({"type": "mesh", "file": "../meshes/pyramid.obj", "material": data["shapes"][0]["material"],
                           "to_world": [[0.5, 0, 0, -0.2], [0, 0.5, 0, -1], [0, 0, 0.5, 0.3], [0, 0, 0, 1]]})
    path = tmp_path / "scenes" / "room.json"
    path.write_text(json.dumps(data))
    sc = load(str(path))
    src = source_of(sc)
    assert src.name is None and sorted(rel for rel, _ in src.files) == ["meshes/pyramid.obj", "scenes/room.json"]
    kw = dict(sampler="bose", spp=16, seed=2, width=12, height=10)
    want = render(sc, **kw).image
    with cluster.engine(scheduler=scheduler) as eng:
        got = render_on(eng, sc, **kw).image
        # each worker loaded the scene from the bytes it was sent, in its own folder
        paths = eng.client.run(_loaded_paths)
    np.testing.assert_array_equal(bits(got), bits(want))
    loaded = [p for ps in paths.values() for p in ps if p.endswith("room.json")]
    assert loaded and all("pyoa-scenes-" in p and not p.startswith(str(tmp_path)) for p in loaded), paths


def _loaded_paths():
    from pyoa.render import scene_source

    return [s.path for s in scene_source._LOADED.values()]


@pytest.mark.parametrize("argv, match", [
    (["render", "cornell", "--progressive", "--sampler", "faure", "--workers", "2", "--out", "{tmp}/p.exr"],
     "--progressive runs in-process"),
    (["study", "dof7d", "cornell", "--reference", "{tmp}/a.exr", "--out", "{tmp}/o"],
     "does not say its scene, and this study has 2"),
    (["study", "dof7d", "--reference", "{tmp}/a.exr", "--reference-spp", "64", "--out", "{tmp}/o"], "not both"),
    (["study", "dof7d", "--out", "{tmp}/o"], "a study needs references"),
    (["study", "dof7d", "--reference-spp", "64", "--spp", "16,x", "--out", "{tmp}/o"], "'x' is not an integer"),
    (["study", "dof7d", "--reference-spp", "64", "--seeds", "0", "--out", "{tmp}/o"], "--seeds must be"),
])
def test_refusals_before_anything_starts(tmp_path, capsys, monkeypatch, argv, match):
    def no_engine(*a, **k):
        raise AssertionError("an engine was started")

    monkeypatch.setattr(cluster, "engine", no_engine)
    with pytest.raises(SystemExit) as exc:
        main([a.format(tmp=tmp_path) for a in argv] + ["-q"])
    assert exc.value.code == 2
    assert match in capsys.readouterr().err


def test_a_csv_that_is_not_a_study_is_refused(inprocess_study, tmp_path, capsys):
    import shutil

    from pyoa.study import FIELDS

    out = tmp_path / "copy"
    shutil.copytree(inprocess_study, out)
    (out / "study.csv").write_text("a,b,c\n1,2,3\n")
    with pytest.raises(SystemExit):
        main(["study", *STUDY, "--out", str(out)])
    assert "is not a pyoa study's CSV" in capsys.readouterr().err
    (out / "study.csv").write_text(",".join(FIELDS) + "\ndof7d,bose,16,16,0,x,1,1,1\n")
    with pytest.raises(SystemExit):
        main(["study", *STUDY, "--out", str(out)])
    assert "a row that is not a study's" in capsys.readouterr().err


def test_a_worker_refuses_a_scene_that_is_not_the_clients():
    from dataclasses import replace

    from pyoa.render import scene_source

    src = scene_source.source_of(load("cornell"))
    with pytest.raises(ValueError, match="is not the client's"):
        scene_source.load_source(replace(src, digest="0" * 64))
