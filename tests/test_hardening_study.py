"""Hardening of ``pyoa study`` (issue 33, items 4, 5, 7, 10 and 13, and its
review): a refused run writes nothing, a study's reference is known by its
pixels and the settings that made it, one run at a time holds a study's
directory (a lock file of the umask's mode, never followed), a row is
counted once, samplers are stored as the catalogue names them, the scenes'
sizes and ``study.json`` are checked before any work, a study's files that
are not regular files are refused (never read), and an older study.json's
reference identity is never taken on trust.

Refusals run the command in a subprocess (exit status 2, one line, the
study's files untouched); runs that succeed run in-process, on copies of
one tiny module-scoped study."""

from __future__ import annotations

import fcntl
import json
import os
import shutil
import socket
import stat
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio
import pytest

from pyoa import study
from pyoa.commands import main
from pyoa.render.image import read_image
from pyoa.render.reference import reference_noise
from pyoa.render.scene import bundled

from .test_hardening_cli import _limit_memory, assert_refused, pyoa

#: The shared study: 2 samplers, 1 count, 2 seeds, 8 x 8, a reference of 2 passes of 64 spp.
ARGS = ["dof7d", "--samplers", "bose,sobol", "--spp", "16", "--seeds", "2", "--size", "8", "8", "--pass-spp", "64",
        "-q"]
REF = ["--reference-spp", "128"]
#: The study's lock file (docs/distributed.md).
LOCK = ".lock"
FILES = ("study.csv", "study.json", "reference-dof7d.exr", "reference-dof7d.variance.exr")


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    """A finished study (4 rows), made once."""
    out = tmp_path_factory.mktemp("study") / "made"
    assert main(["study", *ARGS, *REF, "--out", str(out)]) == 0
    return out


@pytest.fixture
def d(made, tmp_path):
    """A copy of the finished study (bytes and mtimes kept) for one test to change."""
    out = tmp_path / "d"
    shutil.copytree(made, out)
    return out


def snapshot(d) -> dict:
    """Bytes and mtime of the study's files."""
    return {n: ((d / n).read_bytes(), (d / n).stat().st_mtime_ns) for n in FILES}


def last_run(d) -> dict:
    return json.loads((d / "study.json").read_text())["runs"][-1]


# -- item 4: a refused run keeps the reference; a reference is its pixels --------------------------


def test_a_refused_reference_change_writes_nothing_and_the_study_goes_on(d):
    before = snapshot(d)
    res = pyoa("study", *ARGS, "--reference-spp", "256", "--out", d)
    assert snapshot(d) == before  # the reference and its variance too
    assert_refused(res, "study", f"{d} holds dof7d renders measured against a reference of 128 spp in 2 passes of "
                                 "64 (--reference-spp 128 --pass-spp 64), not one of 256 spp in 4 passes of 64; give "
                                 "the reference they used, or another --out")
    # the first command goes on: nothing rendered again, the reference as it was
    assert main(["study", *ARGS, *REF, "--out", str(d)]) == 0
    assert last_run(d)["rendered"] == 0
    assert snapshot(d)["reference-dof7d.exr"] == before["reference-dof7d.exr"]


def test_a_reference_written_again_with_the_same_pixels_is_the_same_reference(d):
    """Other file bytes (another compression, another time stamp), the same pixels: not rendered again."""
    path = d / "reference-dof7d.exr"
    pixels, first = read_image(path), path.read_bytes()
    spec = oiio.ImageSpec(8, 8, 3, "float")
    spec.attribute("compression", "none")
    spec.attribute("Software", "another writer")
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), spec) and out.write_image(pixels) and out.close()
    again = path.read_bytes()
    assert again != first
    assert main(["study", *ARGS, *REF, "--out", str(d)]) == 0
    assert last_run(d)["rendered"] == 0 and path.read_bytes() == again  # used as it is


# -- item 5: one run at a time; a row counted once ------------------------------------------------


def test_a_second_run_on_one_directory_is_refused_naming_the_holder(d):
    before = snapshot(d)
    with open(d / LOCK, "a+") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)  # this test holds the study, as a running study does
        fh.truncate(0)
        fh.write(f"{os.getpid()} {socket.gethostname()}\n")
        fh.flush()
        res = pyoa("study", *ARGS, *REF, "--out", d)
    assert_refused(res, "study", f"study directory {d} is in use by process {os.getpid()} on "
                                 f"{socket.gethostname()}; wait for it or use another --out")
    assert snapshot(d) == before


def test_duplicate_rows_are_counted_once(d, made, capsys):
    """A study.csv with every row twice (two runs at once, before the lock): each row counts once,
    the file is rewritten without the copies, and stderr says so."""
    csv_path = d / "study.csv"
    lines = csv_path.read_text().splitlines(keepends=True)
    csv_path.write_text("".join(lines + lines[1:]))
    assert main(["study", *ARGS, *REF, "--out", str(d)]) == 0
    err = capsys.readouterr().err
    assert f"{csv_path}: dropped 4 duplicate rows" in err and "rewrote the file" in err, err
    assert csv_path.read_bytes() == (made / "study.csv").read_bytes() and last_run(d)["rendered"] == 0
    md, want = (d / "study.md").read_text(), (made / "study.md").read_text()
    assert "Seeds per cell: 2." in md
    table = [line for line in want.splitlines() if line.startswith("| ")]
    assert table and all(line in md for line in table)  # the same means and intervals


def test_duplicate_rows_that_disagree_are_refused(d, capsys):
    csv_path = d / "study.csv"
    lines = csv_path.read_text().splitlines(keepends=True)
    fields = lines[1].split(",")
    fields[5] = repr(float(fields[5]) * 2)  # relmse
    csv_path.write_text("".join([*lines, ",".join(fields)]))
    before = snapshot(d)
    with pytest.raises(SystemExit) as exc:
        main(["study", *ARGS, *REF, "--out", str(d)])
    err = capsys.readouterr().err.strip()
    assert exc.value.code == 2 and len(err.splitlines()) == 1, err
    assert f"{csv_path}: lines 2 and 6 are two renders of dof7d with bose at 16 spp, seed 0, with different " \
           "errors" in err
    assert snapshot(d) == before


# -- item 7: catalogue names -----------------------------------------------------------------------


def test_samplers_are_stored_as_the_catalogue_spells_them(d, made):
    argv = [a if a != "bose,sobol" else "BOSE,Sobol" for a in ARGS]
    assert main(["study", *argv, *REF, "--out", str(d)]) == 0
    assert last_run(d)["rendered"] == 0
    assert (d / "study.csv").read_bytes() == (made / "study.csv").read_bytes()
    md = (d / "study.md").read_text()
    assert "## Headline" in md and "| bose |" in md and "BOSE" not in md
    # rows of a study that stored the names as typed are read as the catalogue's, and rewritten so
    csv_path = d / "study.csv"
    csv_path.write_text(csv_path.read_text().replace(",bose,", ",BOSE,").replace(",sobol,", ",Sobol,"))
    assert main(["study", *ARGS, *REF, "--out", str(d)]) == 0
    assert last_run(d)["rendered"] == 0
    assert csv_path.read_bytes() == (made / "study.csv").read_bytes()


# -- item 10: every scene's size before any work ---------------------------------------------------


def test_scenes_of_two_sizes_are_refused_before_any_work(tmp_path):
    data = json.loads(open(bundled()["dof7d"]).read())
    data["film"] = {"width": 8, "height": 6}
    (tmp_path / "small.json").write_text(json.dumps(data))
    out = tmp_path / "two"
    res = pyoa("study", "dof7d", tmp_path / "small.json", "--samplers", "bose", "--spp", "16", "--seeds", "1",
               "--reference-spp", "16", "--pass-spp", "16", "-q", "--out", out)
    assert [p.name for p in out.iterdir()] == [LOCK]  # no reference rendered
    assert_refused(res, "study", "dof7d renders 256 x 256 and small 8 x 6; a study has one size: give --size W H")


# -- item 13: study.json checked when it is read ---------------------------------------------------


def damage_json(d, damage) -> None:
    path = d / "study.json"
    settings = json.loads(path.read_text())
    damage(settings)
    path.write_text(json.dumps(settings))


@pytest.mark.parametrize("damage, says", [
    pytest.param(lambda s: s["scenes"].update(dof7d="x"), 'scenes["dof7d"] is not an object', id="scene"),
    pytest.param(lambda s: s["runs"][0].pop("seconds"), "runs[0] has no 'seconds'", id="seconds"),
    pytest.param(lambda s: s.update(runs=5), "runs is 5, not a list of runs", id="runs"),
])
def test_a_damaged_study_json_is_refused_naming_the_field(d, damage, says):
    damage_json(d, damage)
    before = snapshot(d)
    res = pyoa("study", *ARGS, *REF, "--out", d)
    assert snapshot(d) == before
    assert_refused(res, "study", f"{d / 'study.json'}: {says}; the file is damaged: move it and "
                                 f"{d / 'study.csv'} away to start the study afresh, or give another --out")


@pytest.mark.parametrize("damage, says", [
    pytest.param(lambda s: s["scenes"]["dof7d"].update(noise=[1, "x"]),
                 'scenes["dof7d"].noise is [1, "x"], not null or a list of 2 numbers >= 0', id="noise"),
    pytest.param(lambda s: s.update(size=[8]), "size is [8], not a list of 2 integers >= 1", id="size"),
    pytest.param(lambda s: s["scenes"]["dof7d"].pop("digest"), 'scenes["dof7d"] has no \'digest\'', id="digest"),
    pytest.param(lambda s: s["runs"][0].update(seconds=float("nan")), "runs[0].seconds is NaN, not a number >= 0",
                 id="nan"),
])
def test_every_field_of_study_json_is_checked(d, capsys, damage, says):
    """The same check for every field pyoa reads (in-process: the subprocess cases above show the command)."""
    damage_json(d, damage)
    before = snapshot(d)
    with pytest.raises(SystemExit) as exc:
        main(["study", *ARGS, *REF, "--out", str(d)])
    err = capsys.readouterr().err.strip()
    assert exc.value.code == 2 and len(err.splitlines()) == 1 and f"{d / 'study.json'}: {says}; " in err, err
    assert snapshot(d) == before


def test_pixel_identity_is_of_the_pixels():
    a = np.arange(12, dtype=np.float32).reshape(2, 2, 3)
    assert study.pixel_identity(a) == study.pixel_identity(a.astype(np.float64))
    assert study.pixel_identity(a) != study.pixel_identity(a.reshape(1, 4, 3))  # the shape counts
    b = a.copy()
    b[1, 1, 2] = np.nextafter(b[1, 1, 2], np.float32(100))
    assert study.pixel_identity(a) != study.pixel_identity(b)


# -- review: the lock file -------------------------------------------------------------------------


def test_the_lock_file_gets_the_mode_of_every_output(tmp_path):
    """0o666 less the umask, as pyoa.util.atomic gives its outputs: under umask 002 (a group-shared --out) the
    group may open it for writing too."""
    old = os.umask(0o002)
    try:
        with study.lock_study(tmp_path):
            pass
    finally:
        os.umask(old)
    assert stat.S_IMODE(os.stat(tmp_path / LOCK).st_mode) == 0o664


def test_a_lock_file_it_may_only_read_is_locked_read_only(tmp_path, monkeypatch):
    """Another user's .lock that this user may not write (os.open refuses O_RDWR with EACCES, as it does for
    anyone but root): the lock is taken through a read-only descriptor, the file is left as it is, and a second
    run, told only of an ended process, names none."""
    path = tmp_path / LOCK
    ended = f"{1 << 22 | 1} {socket.gethostname()}\n"  # above any pid_max: no such process
    path.write_text(ended)
    real_open = os.open

    def denied(p, flags, *mode):
        if os.fspath(p) == str(path) and flags & os.O_RDWR:
            raise PermissionError(13, "Permission denied")
        return real_open(p, flags, *mode)

    monkeypatch.setattr(os, "open", denied)
    with study.lock_study(tmp_path):
        with open(path) as other, pytest.raises(BlockingIOError):
            fcntl.flock(other, fcntl.LOCK_EX | fcntl.LOCK_NB)  # held
        with pytest.raises(ValueError, match=f"^study directory {tmp_path} is in use by another process; "):
            with study.lock_study(tmp_path):
                pass
    assert path.read_text() == ended


# -- review: a study's files that are not regular files --------------------------------------------


ZERO = (lambda p: p.symlink_to("/dev/zero"), "a symlink to '/dev/zero', a character device")
FIFO = (os.mkfifo, "a FIFO (named pipe)")
#: The files a study's run reads first, each replaced by one that is not a regular file (a read of /dev/zero
#: never ends, one of a FIFO blocks): name -> (the file, how it is made, what the refusal calls it).
NOT_REGULAR = {
    "study.csv-dev-zero": ("study.csv", *ZERO),
    "study.csv-fifo": ("study.csv", *FIFO),
    "study.json-dev-zero": ("study.json", *ZERO),
    "study.json-fifo": ("study.json", *FIFO),
}
WHOSE = {"study.csv": "the study's rows", "study.json": "the study's settings"}


def kept(d) -> dict:
    """Each entry of ``d`` but a regular lock file (a run that takes the lock writes its name there): its bytes,
    or its kind and target, and its mtime."""
    out = {}
    for name in sorted(os.listdir(d)):
        st = os.lstat(d / name)
        if name == LOCK and stat.S_ISREG(st.st_mode):
            continue
        body = ((d / name).read_bytes() if stat.S_ISREG(st.st_mode) else
                (stat.S_IFMT(st.st_mode), os.readlink(d / name) if stat.S_ISLNK(st.st_mode) else None))
        out[name] = (body, st.st_mtime_ns)
    return out


@pytest.fixture(scope="module")
def not_regular(made, tmp_path_factory):
    """Every case of NOT_REGULAR, each on its own copy of the study, run at once (each child is a third of a
    second of imports) under the memory cap and a timeout, so that a read without end or a hang fails its
    case: name -> (CompletedProcess, or None when it hung; the copy; its entries before)."""
    started = {}
    for name, (file, make, _) in NOT_REGULAR.items():
        d = tmp_path_factory.mktemp("not-regular") / "d"
        shutil.copytree(made, d)
        (d / file).unlink()
        make(d / file)
        child = subprocess.Popen([sys.executable, "-m", "pyoa", "study", *ARGS, *REF, "--out", str(d)],
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                 env={**os.environ, "PYOA_BACKEND": "numpy"}, preexec_fn=_limit_memory)
        started[name] = (child, d, kept(d))
    results = {}
    for name, (child, d, before) in started.items():
        try:
            out, err = child.communicate(timeout=60)
            res = subprocess.CompletedProcess(child.args, child.returncode, out, err)
        except subprocess.TimeoutExpired:  # a hang fails its own case, not the others
            child.kill()
            child.communicate()
            res = None
        results[name] = (res, d, before)
    return results


@pytest.mark.parametrize("name", NOT_REGULAR)
def test_a_study_file_that_is_not_a_regular_file_is_refused_unread(not_regular, name):
    res, d, before = not_regular[name]
    file, _, is_what = NOT_REGULAR[name]
    assert res is not None, f"{name}: no answer within 60 s"
    assert_refused(res, "study", f"{str(d / file)!r} ({WHOSE[file]}) is {is_what}, not a regular file; remove or "
                                 "rename it, or give another --out")
    assert kept(d) == before


def test_a_study_json_over_its_cap_is_refused_unread(tmp_path):
    """Its bytes are read up to the cap and no further (a file of zeros: sparse, so quick to make)."""
    path = tmp_path / "study.json"
    with open(path, "wb") as fh:
        fh.truncate(study.MAX_SETTINGS_BYTES + 1)
    with pytest.raises(ValueError, match=f"^{path} holds over 64 MiB, not a study's settings; the file is damaged"):
        study.load_settings(path)


def test_a_lock_file_that_is_a_symlink_is_refused_not_followed(d):
    """Followed, the lock's truncation emptied the file it names."""
    victim = d / "victim.txt"
    victim.write_text("precious\n")
    (d / LOCK).unlink()
    (d / LOCK).symlink_to(victim)
    before = kept(d)
    with pytest.raises(ValueError) as exc:
        with study.lock_study(d):
            pass
    assert str(exc.value) == (f"{str(d / LOCK)!r} (the study's lock file) is a symlink to "
                              f"{os.path.realpath(victim)!r}, not a regular file; remove it, or give another --out")
    assert kept(d) == before


def test_a_reference_that_is_not_a_regular_file_is_refused_unread(d, capsys):
    """Given to OpenImageIO, a FIFO would block it for ever and /dev/zero be read (the check is the same)."""
    (d / "ref.exr").symlink_to("/dev/zero")
    with pytest.raises(SystemExit) as exc:
        main(["study", *ARGS, "--reference", str(d / "ref.exr"), "--out", str(d)])
    err = capsys.readouterr().err.strip()
    assert exc.value.code == 2 and err == (f"pyoa study: error: {str(d / 'ref.exr')!r} (--reference) is a symlink to "
                                           "'/dev/zero', a character device, not a regular file; give the reference "
                                           "image itself"), err


def test_a_variance_file_that_is_not_a_regular_file_is_refused(d):
    """Not taken for a reference without one (its noise would go uncorrected without a word)."""
    ref = d / "reference-dof7d.exr"
    variance = d / "reference-dof7d.variance.exr"
    variance.unlink()
    os.mkfifo(variance)
    with pytest.raises(ValueError, match=f"^{str(variance)!r} \\(the variance of a reference\\) is a FIFO"):
        reference_noise(ref, read_image(ref)[..., :3], (2, 2, 4, 4))


# -- review: a reference known by its file's bytes -------------------------------------------------


def test_an_old_identity_is_never_taken_on_trust_and_the_original_file_recovers_it(d, tmp_path, capsys):
    """A study.json of pyoa before pixel identities names the reference by its file's SHA-256. Its file
    written again with the same pixels (as a reference rendered again is: an EXR carries its time) cannot be
    checked against that, nor can a reference rendered again once the file is lost: refused before anything
    is rendered or written, saying what to do; the original file, given, is recognised, and its pixel
    identity replaces the old one."""
    path = d / "reference-dof7d.exr"
    original = tmp_path / "original.exr"
    shutil.copy2(path, original)
    damage_json(d, lambda s: s["scenes"]["dof7d"].update(reference=study.file_digest(original)))
    spec = oiio.ImageSpec(8, 8, 3, "float")
    spec.attribute("compression", "none")
    out = oiio.ImageOutput.create(str(path))
    assert out.open(str(path), spec) and out.write_image(read_image(original)[..., :3]) and out.close()
    cases = ((REF, f"{path} is not that file", f" (or put it back at {path})"),
             (["--reference", path], f"{path} is not that file", ""),
             (REF, f"{path} is missing", f" (or put it back at {path})"))
    for k, (argv, there, back) in enumerate(cases):
        if k == 2:
            path.unlink()  # lost: not rendered again either
        before = kept(d)
        with pytest.raises(SystemExit) as exc:
            main(["study", *ARGS, *map(str, argv), "--out", str(d)])
        err = capsys.readouterr().err.strip()
        assert exc.value.code == 2 and len(err.splitlines()) == 1, err
        assert err == (f"pyoa study: error: {d / 'study.json'} (of an older pyoa) knows the reference of its dof7d "
                       "rows, a reference of 128 spp in 2 passes of 64 (--reference-spp 128 --pass-spp 64), only by "
                       f"the SHA-256 of its file, and {there}: no other file can be checked against that, not even "
                       "one of the same pixels (an EXR carries the time it was written, so a reference rendered "
                       f"again never matches); give the original file with --reference{back}, or give another "
                       "--out"), err
        assert kept(d) == before  # nothing rendered, nothing written
    assert main(["study", *ARGS, "--reference", str(original), "--out", str(d)]) == 0
    assert last_run(d)["rendered"] == 0
    assert json.loads((d / "study.json").read_text())["scenes"]["dof7d"]["reference"] == \
        study.pixel_identity(read_image(original)[..., :3])


# -- review: sampler names by the catalogue's own lookup -------------------------------------------


def test_rows_name_samplers_by_the_catalogues_own_lookup(d, made, monkeypatch):
    """Whatever names the catalogue accepts for a sampler (here an alias it is given), a row's is read as
    the catalogue's name for it: the study repeats no rule of its own."""
    real = study.catalogue.get
    monkeypatch.setattr(study.catalogue, "get", lambda name: real({"oa-bose": "bose"}.get(name, name)))
    csv_path = d / "study.csv"
    csv_path.write_text(csv_path.read_text().replace(",bose,", ",oa-bose,"))
    assert study.read_rows(csv_path) == study.read_rows(made / "study.csv")


def test_run_study_takes_a_settings_value_and_refuses_before_any_work(tmp_path):
    """pyoa.study.run_study(StudySettings(...)) is the library form of ``pyoa study``: sequences are
    accepted for the samplers and counts, and a study without references is refused (ValueError naming
    both ways to give them) before its directory is made."""
    s = study.StudySettings(scenes=["cornell"], out=tmp_path / "s", samplers=("bose", "sobol"), spp=(16, 64))
    assert (s.scenes, s.samplers, s.spp) == (("cornell",), "bose,sobol", "16,64")
    with pytest.raises(ValueError, match="a study needs references: --reference SCENE=REF.exr"):
        study.run_study(s)
    assert not (tmp_path / "s").exists()
    with pytest.raises(ValueError, match="--spp: 'x' is not an integer"):
        study.run_study(study.StudySettings(scenes=("cornell",), out=tmp_path / "t", spp="16,x",
                                            reference_spp=64))
