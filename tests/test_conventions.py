"""One convention across the commands (issue 48, items 11 and 13): how a study is given its references
(``--reference SCENE=FILE``, in any order with the scenes), what the report says of a given reference,
``--size`` (an image's W H; a figure's width is ``--figure-width``), the reference's size, sampler names
shown and stored, one default list of samplers, ``--backend``/``--device`` on every command that generates
samples, ``pyoa --version``, help text for every option, and singular counts.

Each runs the CLI as a user does (``python -m pyoa``) at 8 x 8 pixels and a few samples.
"""

from __future__ import annotations

import argparse
import csv
import json
import struct
import subprocess
import sys

import pytest

SIZE = ["--size", "8", "8"]


def pyoa(*argv, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "pyoa", *map(str, argv)], capture_output=True, text=True,
                          cwd=cwd, timeout=600)


def ok(res) -> subprocess.CompletedProcess:
    assert res.returncode == 0, (res.returncode, res.stdout, res.stderr)
    return res


def refused(res, command: str, *words: str) -> str:
    """Exit status 2 and one line ``pyoa COMMAND: error: ...`` holding ``words``."""
    assert res.returncode == 2, (res.returncode, res.stdout, res.stderr)
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"pyoa {command}: error: "), res.stderr
    assert all(w in lines[0] for w in words), lines[0]
    return lines[0]


@pytest.fixture(scope="module")
def refs(tmp_path_factory):
    """8 x 8 references of cornell (4 passes of 16 spp, with its variance file) and deep."""
    d = tmp_path_factory.mktemp("refs")
    ok(pyoa("reference", "cornell", *SIZE, "--spp", "64", "--pass-spp", "16", "--out", d / "cref.exr", "-q"))
    ok(pyoa("reference", "deep", *SIZE, "--spp", "32", "--pass-spp", "16", "--out", d / "dref.exr", "-q"))
    return d


BASE = ["--samplers", "bose,jittered2d", "--spp", "4", "--seeds", "2", "-q"]
STUDY = [*BASE, *SIZE]


def rows(d) -> list[tuple]:
    with open(d / "study.csv", newline="") as fh:
        return [(r["scene"], r["sampler"], r["seed"], r["relmse"]) for r in csv.DictReader(fh)]


# -- item 11: a study's references -------------------------------------------------------------------


def test_study_reference_before_or_after_the_scene_is_the_same_study(refs, tmp_path):
    """``--reference`` takes one file: it no longer swallows the scene that follows it ("required: SCENE"),
    and the scene first, the reference first or ``SCENE=FILE`` give the same renders and errors."""
    ref = refs / "cref.exr"
    runs = {"after": ["cornell", "--reference", ref],
            "before": ["--reference", ref, "cornell"],
            "named": ["--reference", f"cornell={ref}", "cornell"]}
    got = {}
    for name, argv in runs.items():
        ok(pyoa("study", *argv, *STUDY, "--out", tmp_path / name))
        got[name] = rows(tmp_path / name)
        settings = json.loads((tmp_path / name / "study.json").read_text())
        assert settings["size"] == [8, 8]
    assert len(got["after"]) == 4
    assert got["before"] == got["after"] == got["named"]


def test_study_references_are_matched_by_scene_not_by_position(refs, tmp_path):
    ok(pyoa("study", "cornell", "deep", "--reference", f"deep={refs / 'dref.exr'}",
            "--reference", f"cornell={refs / 'cref.exr'}", *STUDY, "--out", tmp_path / "s"))
    scenes = json.loads((tmp_path / "s" / "study.json").read_text())["scenes"]
    assert scenes["cornell"]["reference_name"] == str(refs / "cref.exr")
    assert scenes["deep"]["reference_name"] == str(refs / "dref.exr")


@pytest.mark.parametrize("argv, words", [
    # a bare file cannot say which of two scenes it is for
    (["cornell", "deep", "--reference", "{ref}"], ["does not say its scene", "--reference cornell={ref}"]),
    (["cornell", "deep", "--reference", "cornell={ref}"], ["no --reference for deep", "deep=REF.exr"]),
    (["cornell", "--reference", "dof7d={ref}"], ["'dof7d' is not a scene of this study (cornell)",
                                                 "SCENE=FILE"]),
    (["cornell", "--reference", "cornell={ref}", "--reference", "cornell={ref}x"], ["two references for cornell"]),
    (["cornell", "--reference", "cornell="], ["names no file", "cornell=FILE"]),
])
def test_study_reference_refusals_say_scene_equals_file(refs, tmp_path, argv, words):
    ref = str(refs / "cref.exr")
    res = pyoa("study", *[a.replace("{ref}", ref) for a in argv], *STUDY, "--out", tmp_path / "s")
    refused(res, "study", *[w.replace("{ref}", ref) for w in words])
    assert not (tmp_path / "s").exists()  # refused before the study's directory is made


def test_study_report_gives_the_given_references_passes(refs, tmp_path):
    """The report read "from the per-pixel variance of its None passes" for a given reference: the count
    comes from the reference's header (pyoa:passes, 64 spp in passes of 16)."""
    ok(pyoa("study", "cornell", "--reference", refs / "cref.exr", *STUDY, "--out", tmp_path / "s"))
    md = (tmp_path / "s" / "study.md").read_text()
    assert "None passes" not in md
    assert "from the per-pixel variance of its 4 passes" in md
    assert json.loads((tmp_path / "s" / "study.json").read_text())["scenes"]["cornell"]["reference_passes"] == 4


# -- item 13: one convention -------------------------------------------------------------------------


def test_study_and_compare_take_the_references_size_and_refuse_another(refs, tmp_path):
    ref = refs / "cref.exr"  # 8 x 8; cornell renders 256 x 256 by default
    ok(pyoa("compare", "cornell", "--samplers", "bose", "--spp", "4", "--reference", ref, "--out", tmp_path / "c",
            "-q"))
    ok(pyoa("study", "cornell", "--reference", ref, *BASE, "--out", tmp_path / "s"))
    assert json.loads((tmp_path / "s" / "study.json").read_text())["size"] == [8, 8]
    refused(pyoa("compare", "cornell", "--samplers", "bose", "--spp", "4", "--size", "16", "16", "--reference", ref,
                 "--out", tmp_path / "c2", "-q"), "compare", "8 x 8", "16 x 16")
    refused(pyoa("study", "cornell", "--reference", ref, *BASE, "--size", "16", "16", "--out", tmp_path / "s2"),
            "study", "8 x 8", "16 x 16")


def test_alias_shown_beside_the_catalogue_name_which_files_store(refs, tmp_path):
    """``orthogonal`` is Mitsuba's name for bose: compare and study both show ``bose (orthogonal)`` in their
    tables and store ``bose`` in their CSVs (compare used to keep ``orthogonal`` in both)."""
    ref = refs / "cref.exr"
    ok(pyoa("compare", "cornell", "--samplers", "orthogonal,stratified", "--spp", "4", "--reference", ref,
            "--out", tmp_path / "c", "-q"))
    md = (tmp_path / "c.md").read_text()
    assert "| bose (orthogonal) |" in md and "| jittered2d (stratified) |" in md and "/ bose (orthogonal)" in md
    with open(tmp_path / "c.csv", newline="") as fh:
        assert [r["sampler"] for r in csv.DictReader(fh)] == ["bose", "jittered2d"]
    ok(pyoa("study", "cornell", "--reference", ref, "--samplers", "orthogonal,stratified", "--spp", "4",
            "--seeds", "2", *SIZE, "-q", "--out", tmp_path / "s"))
    md = (tmp_path / "s" / "study.md").read_text()
    assert "| bose (orthogonal) |" in md and "| jittered2d (stratified) |" in md
    assert {r[1] for r in rows(tmp_path / "s")} == {"bose", "jittered2d"}


def test_study_headline_names_only_the_padded_samplers_that_ran(refs, tmp_path):
    ok(pyoa("study", "cornell", "--reference", refs / "cref.exr", *STUDY, "--out", tmp_path / "s"))
    md = (tmp_path / "s" / "study.md").read_text()
    head = md[md.index("## Headline"):]
    assert "the best padded sampler is the one of jittered2d with" in head
    for name in ("cmj2d", "sobol02", "zsobol", "pmj02"):
        assert name not in head, head


def _parser():
    from pyoa.commands.main import build_parser

    return build_parser()


def _subparsers(ap) -> dict:
    action = next(a for a in ap._actions if isinstance(a, argparse._SubParsersAction))
    return action.choices


def test_compare_and_study_default_to_one_list_of_samplers():
    subs = _subparsers(_parser())
    defaults = {c: next(a.default for a in subs[c]._actions if a.dest == "samplers") for c in ("compare", "study")}
    assert defaults["compare"] == defaults["study"], defaults


GENERATORS = {
    "points": ["bose", "--spp", "16", "--out", "{tmp}/p.npy"],
    "plot": ["bose", "--spp", "16", "--out", "{tmp}/p.png"],
    "spectrum": ["bose", "--spp", "16", "--out", "{tmp}/s.png"],
    "render": ["cornell", *SIZE, "--spp", "4", "--out", "{tmp}/r.exr"],
    "compare": ["cornell", *SIZE, "--spp", "4", "--samplers", "bose", "--reference", "{ref}", "--out", "{tmp}/c"],
    "reference": ["cornell", *SIZE, "--spp", "16", "--pass-spp", "16", "--out", "{tmp}/ref.exr"],
    "study": ["cornell", *SIZE, "--spp", "4", "--seeds", "2", "--reference-spp", "16", "--out", "{tmp}/st"],
}


@pytest.mark.parametrize("command", list(GENERATORS))
def test_every_command_that_generates_samples_takes_backend_and_device(refs, tmp_path, command):
    """``--device`` existed only on ``points``; now every such command passes it to its sampler, which
    refuses an empty selector (whatever the backend) before any work."""
    argv = [a.replace("{tmp}", str(tmp_path)).replace("{ref}", str(refs / "cref.exr")) for a in GENERATORS[command]]
    refused(pyoa(command, *argv, "--backend", "numpy", "--device", ""), command, "device must not be empty")
    assert not [p for p in tmp_path.iterdir() if p.is_file()]
    actions = {c: {o for a in p._actions for o in a.option_strings} for c, p in _subparsers(_parser()).items()}
    assert {"--backend", "--device"} <= actions[command]


def test_every_option_has_help():
    missing = []
    ap = _parser()
    for name, p in {"pyoa": ap, **_subparsers(ap)}.items():
        for a in p._actions:
            if isinstance(a, (argparse._HelpAction, argparse._SubParsersAction)):
                continue
            if not a.help or not str(a.help).strip():
                missing.append(f"{name} {'/'.join(a.option_strings) or a.dest}")
    assert not missing, f"options without help: {missing}"


def test_version():
    from pyoa import __version__

    res = ok(pyoa("--version"))
    assert res.stdout.strip() == f"pyoa {__version__}"


def png_width(path) -> int:
    with open(path, "rb") as fh:
        head = fh.read(24)
    return struct.unpack(">I", head[16:20])[0]


@pytest.mark.parametrize("command", ["plot", "spectrum"])
def test_figure_width_is_not_size(tmp_path, command):
    """``--size`` is W H of an image elsewhere; a figure's width is ``--figure-width PX``, and the old
    ``--size PX`` still works with a note."""
    args = [command, "bose", "--spp", "9", "--backend", "numpy", *(["--trials", "2"] if command == "spectrum" else [])]
    res = ok(pyoa(*args, "--figure-width", "200", "--out", tmp_path / "a.png", "-q"))
    assert png_width(tmp_path / "a.png") == 200 and res.stderr == ""
    res = ok(pyoa(*args, "--size", "120", "--out", tmp_path / "b.png", "-q"))
    assert png_width(tmp_path / "b.png") == 120
    assert res.stderr.strip() == (f"pyoa {command}: note: --size 120 is deprecated and goes in the next release; "
                                  "write --figure-width 120 (--size is W H of an image in every other command)")
    refused(pyoa(*args, "--size", "120", "--figure-width", "200", "--out", tmp_path / "c.png"), command,
            "two figure widths given")


def test_one_worker_is_singular():
    """A cluster of one worker was described as "(1 workers)"."""
    from distributed import LocalCluster

    from pyoa.cluster import engine

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster:
        with engine(scheduler=cluster.scheduler_address) as eng:
            assert eng.description.endswith("(1 worker)"), eng.description
