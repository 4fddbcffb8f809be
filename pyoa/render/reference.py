"""High-spp references as the mean of independent passes, resumable, in-process or on a cluster.

A reference of ``passes`` x ``pass_spp`` samples per pixel is the mean of
``passes`` renders whose sampler seeds are hashes of (seed, pass index)
(:func:`pass_seed`). Each pass is a task of an engine (:mod:`pyoa.cluster`):
in-process they run in order; on a cluster they finish in any order. Either
way the passes join the float64 running sums in pass order (a pass that
finished early waits, saved, for the ones before it), so the reference has
the same bits however it was scheduled, and the state file written after
every finished pass (``OUT.state.npz``, :mod:`.state`) lets a run killed at
any point resume without rendering a finished pass again.

Besides the mean, the passes give the reference's own noise: the per-pixel
variance of the mean, ``(S2 - S1^2 / P) / (P - 1) / P`` from the sum ``S1``
and sum of squares ``S2`` of the P pass images
(:func:`pyoa.analysis.statistics.pass_variance`), written beside the image
as ``OUT.variance.exr`` (:func:`variance_path`). A relative MSE measured
against the reference is too large by about its relMSE-weighted mean
(:func:`pyoa.analysis.statistics.relmse_noise`); ``pyoa study`` reports and
corrects for it.
"""

from __future__ import annotations

import sys
from contextlib import closing
from pathlib import Path

import numpy as np

from .image import check_finite, pixel_digest, write_exr
from .settings import RenderSettings
from .state import (
    BadState,
    check_state_file,
    describe_size,
    read_state_arrays,
    state_path,
    write_state,
)
from .tiles import worker_render

#: Key of the reference passes' seeds (see pass_seed).
REFERENCE_KEY = 0x52454631
#: Version of the state file's layout and key (a state of another version is not resumed).
STATE_VERSION = 3
#: Options named when a state's key differs from this run's (key field -> how to say it).
_KEY_FIELDS = {"version": "another pyoa version",
               "renderer": "another version of pyoa's renderer (its images differ)",
               "scene": "another scene file (or scene contents)",
               "width": "--size", "height": "--size", "max_depth": "--max-depth", "sampler": "--sampler",
               "pass_spp": "--pass-spp", "passes": "--spp", "seed": "--seed", "filter": "--filter",
               "first": "--first", "shading": "--shading"}


def pass_seed(seed: int, k: int) -> int:
    """Sampler seed of reference pass ``k``: a hash of (seed, k), so that no
    pass shares its scramble with a render made with a small seed (a
    reference rendered with seeds 0, 1, ... would share its first samples
    with ``pyoa compare --seed 0`` and flatter that sampler)."""
    from ..reference.hashes import hash_pair

    return hash_pair(seed, k, REFERENCE_KEY)


def variance_path(out) -> Path:
    """Where the reference ``out`` (``NAME.exr``) keeps its per-pixel variance: ``NAME.variance.exr``."""
    out = Path(out)
    return out.with_name(out.name[: -len(out.suffix)] + ".variance.exr" if out.suffix else out.name + ".variance.exr")


#: Header attribute (``pyoa:KEY``) of a variance file: the :func:`~.image.pixel_digest` of its reference.
VARIANCE_OF = "reference_pixels_sha256"
#: Header attributes a reference and its variance file share (:func:`render_reference` writes both):
#: a variance file of before :data:`VARIANCE_OF` whose header differs from its reference's in one is another's.
_SHARED = ("scene_sha256", "width", "height", "sampler", "spp", "seed", "passes", "pass_spp", "max_depth", "filter",
           "shading", "renderer")


def _check_variance_of(vp: Path, path, reference: np.ndarray) -> None:
    """Refuse (ValueError) the variance file ``vp`` unless it is the variance
    of the reference ``path`` whose pixels are ``reference``: its header's
    :data:`VARIANCE_OF` must be their digest. A variance file of pyoa before
    it (no digest) cannot be checked so: refused when the headers say it is
    another image's (the reference's header names another kind, e.g. a
    render written over it, or other settings), else used with a note on
    stderr saying it is unchecked."""
    from .image import read_attributes

    var_meta = read_attributes(vp)
    again = f"remove {vp} (its noise is then unknown) or make the reference again with pyoa reference"
    digest = var_meta.get(VARIANCE_OF)
    if digest is not None:
        if digest != pixel_digest(reference):
            raise ValueError(f"{vp} is the variance of another image than {str(path)!r} (its pixels changed since "
                             f"the variance was written, e.g. an image written over it): {again}")
        return
    ref_meta = read_attributes(path)
    kind = ref_meta.get("kind")
    differ = [k for k in _SHARED if k in ref_meta and k in var_meta and ref_meta[k] != var_meta[k]]
    if (kind is not None and kind != "reference") or differ:
        said = f"their {differ[0]} differs" if differ else f"{str(path)!r} is a {kind}"
        raise ValueError(f"{vp} is not the variance of {str(path)!r} ({said}): {again}")
    print(f"pyoa: note: {vp} does not record which reference it belongs to (written before pyoa recorded it); "
          f"taken as the variance of {str(path)!r} unchecked; make the reference again with pyoa reference to tie "
          "them", file=sys.stderr)


def reference_noise(path, reference: np.ndarray, crop) -> tuple[float, float] | None:
    """How much the reference ``path``'s own noise adds to a relative MSE
    measured against it, over the image and over ``crop``:
    :func:`pyoa.analysis.statistics.relmse_noise` of the per-pixel variance
    in its :func:`variance_path` file; None when it has none (a reference not
    made by ``pyoa reference``, whose noise is unknown). ``reference`` holds
    its pixels (H, W, 3). A variance path that is not a regular file is
    refused (reading a FIFO hangs), not taken for none; one that is not this
    reference's (:func:`_check_variance_of`: its header's digest of the
    reference's pixels, and its size) is refused, never used."""
    from ..analysis.statistics import relmse_noise
    from .image import read_image

    vp = variance_path(path)
    check_state_file(vp, "the variance of a reference", "remove or rename it")
    if not vp.exists():
        return None
    var = read_image(vp, "the variance of a reference")[..., :3].astype(np.float64)
    if var.shape != reference.shape:
        raise ValueError(f"{vp} is {var.shape[1]} x {var.shape[0]}, its reference {reference.shape[1]} x "
                         f"{reference.shape[0]}: not this reference's variance; remove it")
    _check_variance_of(vp, path, reference)
    return relmse_noise(var, reference), relmse_noise(var, reference, crop)


def reference_key(scene, p, *, pass_spp: int, passes: int, seed: int) -> dict:
    """Every setting that changes the bits of a reference of ``passes``
    passes planned as ``p`` (:func:`~pyoa.render.render.plan` of one pass)
    (the backend and the engine do not: every backend gives the same
    samples, every engine the same images)."""
    key = dict(version=STATE_VERSION, **p.identity(scene), pass_spp=pass_spp, passes=passes)
    # a reference is its passes: their count, size and seed replace the one pass's spp (and sobol has no base)
    del key["spp"], key["base"]
    key["seed"] = seed
    return key


def _total_spp(key: dict):
    """--spp of a run from its key (passes x pass_spp); "?" for a key without them."""
    try:
        return int(key["passes"]) * int(key["pass_spp"])
    except (KeyError, TypeError, ValueError):
        return "?"


def describe_change(saved: dict, key: dict) -> str:
    """Why a saved key is not this run's, as the user would set it: the first field that differs."""
    for field, option in _KEY_FIELDS.items():
        if saved.get(field) != key[field]:
            if field in ("scene", "first", "version", "renderer"):
                return f"made with {option}"
            if field in ("width", "height"):
                return describe_size(saved, key)
            if field == "passes":  # say it as the user gave it: --spp, the total
                return f"made with --spp {_total_spp(saved)}, not {_total_spp(key)}"
            return f"made with {option} {saved.get(field)}, not {key[field]}"
    return "made with other settings"  # pragma: no cover - keys differ in a field not listed


class Passes:
    """The running sums of a reference's passes, saved after every pass.

    ``add(k, image)`` takes pass k's float32 image in any order; the sums
    take the passes in order 0, 1, 2, ... (a pass that arrives early is kept,
    and saved, until the ones before it have arrived).

    A state of another run, or one that holds no valid sums, is not resumed
    (a one-line note says why, on stderr); a state path that is not a
    regular file is refused (:func:`.state.check_state_file`, a ValueError).
    """

    def __init__(self, state: Path, key: dict, *, quiet: bool = False, command: str = "pyoa reference"):
        self.state, self.key, self.passes = Path(state), key, int(key["passes"])
        self.shape = (key["height"], key["width"], 3)
        self.total = self.sumsq = None
        self.done, self.pending = 0, {}
        check_state_file(self.state, f"where {command} keeps its running sum")
        if self.state.exists():
            try:
                sums, self.done, self.pending = read_state_arrays(self.state, key, "passes", self.passes,
                                                                  describe_change, ("sum", "sumsq"), pending=True)
            except BadState as why:
                print(f"{command}: not resuming {self.state} ({why}): starting over", file=sys.stderr)
            else:
                if self.done:
                    self.total, self.sumsq = sums["sum"], sums["sumsq"]
                if not quiet:
                    extra = f" (and {len(self.pending)} more, out of order)" if self.pending else ""
                    print(f"resuming {self.state}: {self.done} of {self.passes} passes done{extra}")

    @property
    def todo(self) -> list[int]:
        """Passes still to render, in order."""
        return [k for k in range(self.done, self.passes) if k not in self.pending]

    @property
    def finished(self) -> int:
        """Passes rendered so far (in the sums or waiting for them)."""
        return self.done + len(self.pending)

    def add(self, k: int, image: np.ndarray) -> None:
        """Take pass ``k``'s image, fold every pass now in order into the sums, save."""
        self.pending[k] = np.ascontiguousarray(image, dtype=np.float32)
        while self.done in self.pending:
            img = self.pending.pop(self.done).astype(np.float64)
            self.total = img if self.total is None else self.total + img
            self.sumsq = img * img if self.sumsq is None else self.sumsq + img * img
            self.done += 1
        zero = np.zeros(self.shape)
        order = sorted(self.pending)
        images = np.stack([self.pending[j] for j in order]) if order else np.zeros((0, *self.shape), np.float32)
        write_state(self.state, zero if self.total is None else self.total, "passes", self.done, self.key,
                    sumsq=zero if self.sumsq is None else self.sumsq,
                    pending=np.asarray(order, dtype=np.int64), images=images)

    def mean(self) -> np.ndarray:
        """The reference: float32 mean of every pass (all must be done)."""
        assert self.done == self.passes, (self.done, self.passes)
        return (self.total / self.passes).astype(np.float32)

    def variance(self) -> np.ndarray | None:
        """Per-pixel variance of the mean (None with a single pass: no estimate)."""
        from ..analysis.statistics import pass_variance

        return None if self.passes < 2 else pass_variance(self.total, self.sumsq, self.passes)


def pass_task(scene, settings: RenderSettings, seed: int, k: int, threads: int | None):
    """One reference pass: ``(k, float32 image)``, checked finite."""
    res = worker_render(scene, settings.replace(seed=pass_seed(seed, k)), threads=threads)
    # a NaN pass would spoil every later pass's mean: stop at the first
    check_finite(res.image, f"pass {k}")
    return k, res.image


def render_reference(eng, scene, *, out, key: dict, settings: RenderSettings, seed: int, quiet: bool = False,
                     command: str = "pyoa reference",
                     metadata: dict | None = None) -> tuple[np.ndarray, np.ndarray | None]:
    """Render (or resume) the reference of ``key`` on the engine ``eng``
    and write ``out`` and its variance (:func:`variance_path`); returns
    ``(mean, variance)``. ``settings`` are one pass's (its seed is
    :func:`pass_seed` of ``seed`` and the pass); every check has been made
    by the caller.
    ``metadata`` (:func:`pyoa.render.provenance.describe`) goes into both
    files' headers, with their kinds."""
    from ..util.progress import bar as progress_bar
    from .scene_source import source_of

    state = state_path(out)
    acc = Passes(state, key, quiet=quiet, command=command)
    todo = acc.todo
    src = eng.share(scene if eng.client is None else source_of(scene))
    threads = eng.task_threads()
    results = eng.run(pass_task, [(src, settings, seed, k, threads) for k in todo], key="pyoa-pass")
    with closing(results), progress_bar(total=acc.passes, initial=acc.finished, desc=f"{Path(out).name} passes",
                                unit="pass", disable=quiet) as bar:
        for _, (k, image) in results:
            acc.add(k, image)
            bar.update(1)
    mean, var = acc.mean(), acc.variance()
    meta = metadata or {}
    write_exr(out, mean, dict(meta, kind="reference") if meta else None)
    if var is not None:
        # the digest of the pixels just written ties the variance to them (reference_noise checks it)
        write_exr(variance_path(out), var.astype(np.float32),
                  {**(dict(meta, kind="reference variance") if meta else {}), VARIANCE_OF: pixel_digest(mean)})
    else:
        variance_path(out).unlink(missing_ok=True)  # not a stale one of another run
    state.unlink(missing_ok=True)
    return mean, var
