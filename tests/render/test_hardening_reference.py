"""``pyoa reference`` resumes only a state of its own run: a state of other
settings, or one that is unreadable or holds impossible counts or values,
starts the run over with a one-line note, never a wrong mean or a traceback.

Interruptions are simulated in-process (as in test_render_cli.py); each
corrupt state is made by the code under test and then altered, so these
tests do not depend on the state's format."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from pyoa.commands import main
from pyoa.render import reference
from pyoa.render.image import read_image
from pyoa.render.scene import bundled

from .test_render_cli import record_passes

ARGS = ["--size", "8", "8", "--pass-spp", "4", "-q"]

def interrupt(monkeypatch, argv, fail_at):
    record_passes(monkeypatch, fail_at)
    with pytest.raises(SystemExit, match="^130$"):  # pyoa.commands: Ctrl-C is exit status 130
        main(["reference", *argv])


@pytest.fixture(scope="module")
def full(tmp_path_factory):
    """The uninterrupted 8-spp reference of cornell (2 passes of 4)."""
    out = tmp_path_factory.mktemp("full") / "full.exr"
    assert main(["reference", "cornell", *ARGS, "--spp", "8", "--out", str(out)]) == 0
    return read_image(out)


def rerun_starts_over(monkeypatch, capsys, argv, out, want, reason):
    """Run ``pyoa reference argv``: every pass rendered, the note on stderr,
    the image ``want``, the state removed."""
    capsys.readouterr()
    calls = record_passes(monkeypatch)
    assert main(["reference", *argv]) == 0
    assert calls == [reference.pass_seed(0, 0), reference.pass_seed(0, 1)]
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err, err
    assert err.startswith(f"pyoa reference: not resuming {out}.state.npz (") and err.endswith("): starting over"), err
    assert reason in err, err
    np.testing.assert_array_equal(read_image(out), want)
    assert not (out.parent / (out.name + ".state.npz")).exists()


def test_state_of_a_larger_spp_is_not_resumed(tmp_path, monkeypatch, capsys, full):
    """3 passes saved by a --spp 16 run are not the mean of a --spp 8 run (1.5x too bright)."""
    out = tmp_path / "ref.exr"
    interrupt(monkeypatch, ["cornell", *ARGS, "--spp", "16", "--out", str(out)], fail_at=4)
    rerun_starts_over(monkeypatch, capsys, ["cornell", *ARGS, "--spp", "8", "--out", str(out)], out, full,
                      "made with --spp 16, not 8")


def test_state_of_edited_scene_contents_is_not_resumed(tmp_path, monkeypatch, capsys, full):
    """The same scene path with other contents (a dimmer light) is another scene."""
    scene, out = tmp_path / "cornell.json", tmp_path / "ref.exr"
    data = json.loads(open(bundled()["cornell"]).read())
    light = next(s for s in data["shapes"] if "emission" in s)
    light["emission"] = [v / 2 for v in light["emission"]]
    scene.write_text(json.dumps(data))
    interrupt(monkeypatch, [str(scene), *ARGS, "--spp", "8", "--out", str(out)], fail_at=2)
    shutil.copy(bundled()["cornell"], scene)  # back to the bundled cornell's contents
    rerun_starts_over(monkeypatch, capsys, [str(scene), *ARGS, "--spp", "8", "--out", str(out)], out, full,
                      "made with another scene file (or scene contents)")


def _rewrite(state, **changes):
    """Save the state again with some arrays replaced (None: dropped)."""
    with np.load(state) as st:
        arrays = {k: st[k] for k in st.files}
    arrays.update(changes)
    with open(state, "wb") as fh:
        np.savez(fh, **{k: v for k, v in arrays.items() if v is not None})


def _truncate(state):
    data = state.read_bytes()
    state.write_bytes(data[: len(data) // 2])


def _sum(state):
    with np.load(state) as st:
        return st["sum"]


CORRUPTIONS = {
    "negative count": (lambda s: _rewrite(s, passes=np.int64(-7)), "passes done, not 0 to 2"),
    "count over the total": (lambda s: _rewrite(s, passes=np.int64(5)), "passes done, not 0 to 2"),
    "NaN sum": (lambda s: _rewrite(s, sum=np.full((8, 8, 3), np.nan)), "its sum holds NaN or inf"),
    "inf sum": (lambda s: _rewrite(s, sum=np.full((8, 8, 3), np.inf)), "its sum holds NaN or inf"),
    "wrong shape": (lambda s: _rewrite(s, sum=np.zeros((4, 4, 3))), "its sum is float64 (4, 4, 3)"),
    "float32 sum": (lambda s: _rewrite(s, sum=_sum(s).astype(np.float32)), "its sum is float32"),
    "no key": (lambda s: _rewrite(s, key=None), "unreadable (KeyError"),
    "no sum": (lambda s: _rewrite(s, sum=None), "unreadable (KeyError"),
    "key not JSON": (lambda s: _rewrite(s, key=np.array("{not json")), "its key is not a JSON object"),
    "truncated": (_truncate, "unreadable (BadZipFile"),
    "empty": (lambda s: s.write_bytes(b""), "unreadable ("),
    "not a zip": (lambda s: s.write_text("hello"), "unreadable ("),
}


@pytest.mark.parametrize("corrupt, reason", CORRUPTIONS.values(), ids=list(CORRUPTIONS))
def test_corrupt_state_starts_over(tmp_path, monkeypatch, capsys, full, corrupt, reason):
    out = tmp_path / "ref.exr"
    argv = ["cornell", *ARGS, "--spp", "8", "--out", str(out)]
    interrupt(monkeypatch, argv, fail_at=2)  # one pass saved
    corrupt(tmp_path / "ref.exr.state.npz")
    rerun_starts_over(monkeypatch, capsys, argv, out, full, reason)
