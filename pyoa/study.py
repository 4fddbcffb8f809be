"""``pyoa study``: error against samples per pixel, over seeds, with confidence intervals.

A study renders every (scene, sampler, spp, seed) once and measures its
relative MSE (:func:`pyoa.render.image.rel_mse`, the paper's measure [1]_)
against a high-spp reference of the scene, over the whole image and a crop.
Each render is one task of an engine (:mod:`pyoa.cluster`): in-process by
default, or on a Dask cluster. Rows are appended to ``DIR/study.csv`` as
results arrive, so an interrupted study resumes and renders only what is
missing; ``DIR/study.json`` holds the settings every row depends on (scene
contents, size, crop, path length, filter, shading, references) and a study
of other settings is refused rather than mixed in. Rows and settings name a
sampler by its catalogue name (``BOSE`` is stored as ``bose``; the report
shows an alias beside it, ``bose (orthogonal)``); a reference
is identified by its pixels (:func:`pixel_identity`) and the settings that
rendered it, never by its file's bytes. One run at a time holds the
directory (:func:`lock_study`).

The report (``DIR/study.md``, :func:`report`):

* per (scene, sampler, spp), the mean relMSE over seeds with its 95 %
  Student-t interval (:func:`pyoa.analysis.statistics.mean_ci`);
* the reference's own noise: a reference made by ``pyoa reference`` carries
  the per-pixel variance of its mean (``NAME.variance.exr``), and a relMSE
  measured against it is too large by about
  :func:`~pyoa.analysis.statistics.relmse_noise` of that variance; the
  tables give the measured mean minus that estimate (the interval shifts with
  it), and say so. A reference without a variance file is used as is, and
  the report says its noise is unknown;
* the slope of log error against log spp per sampler
  (:func:`~pyoa.analysis.statistics.fit_loglog`), and a headline: bose
  against the best padded 2D sampler and against sobol, as ratios of means
  with intervals that hold their level at 2 to 8 seeds
  (:func:`~pyoa.analysis.statistics.ratio_ci`).

Figures: ``DIR/study.png`` (every scene) and ``DIR/study-SCENE.png``, error
against spp on log-log axes with the intervals as bands, like the paper's
convergence plots (a band that reaches 0 is cut at the axis and marked).

References
----------
.. [1] W. Jarosz, A. Enayet, A. Kensler, C. Kilpatrick, P. Christensen,
   "Orthogonal Array Sampling for Monte Carlo Rendering", Computer Graphics
   Forum 38(4) (EGSR 2019).
"""

from __future__ import annotations

import csv
import fcntl
import hashlib
import io
import json
import math
import os
import socket
import sys
import time
from contextlib import closing, contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import catalogue
from .analysis.statistics import corrected, fit_loglog, mean_ci, ratio_ci
from .util.atomic import atomic_path, check_not_inputs, check_writable
from .catalogue.entries import MAX_SPP, check_int
from .util.units import format_interval, format_ratio

#: Samplers that stratify pairs of dimensions and pad them (the paper's "(pad)";
#: pbrt-v4's zsobol and pmj02 pad their pairs the same way, docs/samplers.md).
PADDED = ("jittered2d", "cmj2d", "sobol02", "zsobol", "pmj02")
#: Columns of study.csv.
FIELDS = ("scene", "sampler", "spp_asked", "spp", "seed", "relmse", "relmse_crop", "mse", "seconds")
#: Version of study.json (a study of another version is not resumed).
STUDY_VERSION = 1
#: The lock file of a study's directory (:func:`lock_study`).
LOCK_NAME = ".lock"
#: Prefix of a reference's identity in study.json (:func:`pixel_identity`). A
#: bare SHA-256 there is the older identity, the digest of the file's bytes.
PIXELS = "pixels-sha256:"


def parse_list(text: str, what: str) -> list[str]:
    """A comma-separated option as a list of non-empty, distinct items, in order."""
    items = [t.strip() for t in str(text).split(",") if t.strip()]
    if not items:
        raise ValueError(f"{what} {text!r} names nothing; give a comma-separated list")
    return list(dict.fromkeys(items))


def parse_spp(text: str) -> list[int]:
    """``--spp 16,64,256`` as increasing distinct ints in [1, 2^24]."""
    out = []
    for t in parse_list(text, "--spp"):
        try:
            n = int(t)
        except ValueError:
            raise ValueError(f"--spp: {t!r} is not an integer; give counts such as 16,64,256,1024") from None
        out.append(check_int("--spp", n, 1, MAX_SPP, " (the samplers' limit, 2^24)"))
    return sorted(set(out))


def canonical_sampler(name: str) -> str:
    """The catalogue's own spelling of a sampler name (the catalogue looks
    names up case-insensitively: ``BOSE`` is ``bose``); an unknown name fails,
    with the valid ones listed."""
    return catalogue.get(name).name


def sampler_names(text: str) -> list[str]:
    """``--samplers`` as distinct catalogue names, in the catalogue's spelling
    (``all``: every sampler). Rows, settings and the report compare these
    names, so ``--samplers BOSE`` continues a study of ``bose``."""
    return list(sampler_labels(text))


def sampler_labels(text: str) -> dict[str, str]:
    """``--samplers``' catalogue names, each with the name the report's tables show for it: the name
    typed, beside the catalogue's when it is an alias (:func:`pyoa.catalogue.shown`)."""
    if str(text).strip().lower() == "all":
        return {n: n for n in catalogue.names()}
    return catalogue.labels(parse_list(text, "--samplers"))


def reference_files(given: list[str] | None, scenes: list[str]) -> list[str] | None:
    """``--reference`` (repeatable) as one image per scene, in the scenes' order; None without it.

    Each value is ``SCENE=FILE``, SCENE one of ``scenes`` as typed; a bare ``FILE`` only when the
    study has one scene (a file name may hold ``=``: a value whose head is no scene is a file). A
    scene given two images, a scene without one, and an image that names no scene of several are
    refused, each with the form to use."""
    if not given:
        return None
    files: dict[str, str] = {}
    for value in given:
        heads = [s for s in scenes if value.startswith(s + "=")]
        if heads:
            scene = max(heads, key=len)
            file = value[len(scene) + 1:]
            if not file:
                raise ValueError(f"--reference {value!r} names no file; give --reference {scene}=FILE")
        elif "=" in value and not os.path.lexists(value):
            head = value.split("=", 1)[0]
            raise ValueError(f"--reference {value!r}: {head!r} is not a scene of this study "
                             f"({', '.join(scenes)}); give --reference SCENE=FILE")
        elif len(scenes) == 1:
            scene, file = scenes[0], value
        else:
            raise ValueError(f"--reference {value!r} does not say its scene, and this study has {len(scenes)}; "
                             f"give one --reference SCENE=FILE per scene, e.g. --reference {scenes[0]}={value}")
        if files.setdefault(scene, file) != file:
            raise ValueError(f"two references for {scene}: {files[scene]!r} and {file!r}; give one")
    missing = [s for s in scenes if s not in files]
    if missing:
        raise ValueError(f"no --reference for {', '.join(missing)}; give one --reference SCENE=FILE per scene "
                         f"(e.g. --reference {missing[0]}=REF.exr), or --reference-spp N to render them")
    return [files[s] for s in scenes]


@dataclass(frozen=True)
class Job:
    """One render of the study."""

    scene: str
    sampler: str
    spp_asked: int
    spp: int
    seed: int

    @property
    def ident(self) -> tuple:
        return (self.scene, self.sampler, self.spp_asked, self.seed)


def file_digest(path) -> str:
    """SHA-256 of a file's bytes (a reference's identity in a study.json of
    pyoa before :func:`pixel_identity`); only a regular file is read."""
    from .render.state import open_regular

    h = hashlib.sha256()
    with open_regular(path, "a study's reference") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def pixel_identity(pixels: np.ndarray) -> str:
    """A reference's identity: the SHA-256 of its shape and its float32 RGB
    pixels (little-endian). Not of its file: writing the same pixels again
    (an EXR carries the time it was written) keeps the identity."""
    from .render.image import pixel_digest

    return PIXELS + pixel_digest(pixels)


def is_reference(saved: str | None, path: Path, pixels: np.ndarray) -> bool:
    """Whether the identity ``saved`` (study.json's) is the reference
    ``path`` with ``pixels``: its pixel identity, or, in a study.json written
    before pixel identities, the SHA-256 of the file's bytes."""
    if saved is None:
        return False
    if saved.startswith(PIXELS):
        return saved == pixel_identity(pixels)
    return saved == file_digest(path)


# -- the study's directory: settings, rows ------------------------------------------------------


def check_out_dir(out) -> Path:
    """The study's directory: created if missing (its parent must exist);
    refused when it is a file or its files cannot be written."""
    d = Path(out)
    if d.exists() and not d.is_dir():
        raise ValueError(f"--out {str(out)!r} is a file; give a directory for study.csv, study.md and the figures")
    if not d.exists():
        if not d.parent.is_dir():
            raise ValueError(f"--out {str(out)!r}: its parent directory {str(d.parent)!r} does not exist")
        d.mkdir()
    for name in ("study.csv", "study.md", "study.png", "study.json"):
        try:
            check_writable(d / name)
        except OSError as exc:
            raise ValueError(f"--out: {exc}") from None
    return d


@contextmanager
def lock_study(d: Path):
    """Hold the study directory ``d`` for one run: an exclusive
    :func:`fcntl.flock` on ``d/.lock``, which names the holder (``PID
    HOST``). A second run on the same directory is refused at once (two runs
    would append every row twice). The lock is the open file's, so the
    system releases it when the holder exits, however it exits; the file
    stays (removing it would let a third run lock a new file while the
    second waits on the old one).

    The file is made with the mode of every file pyoa writes
    (:func:`pyoa.util.atomic.new_file_mode`), so the users of a group-shared
    ``--out`` can all lock it. One that this user may read but not write
    (made by another user under a stricter umask) is locked through a
    read-only descriptor, which ``flock`` accepts; the run cannot write its
    name there then. A ``.lock`` that is a symlink or not a regular file is
    refused, never followed (truncating it would empty the file it names)."""
    import stat

    from .util.atomic import new_file_mode
    from .render.state import not_regular

    path = d / LOCK_NAME
    what, fix = "the study's lock file", "remove it, or give another --out"
    # O_NONBLOCK: the open of a FIFO does not wait for a writer
    flags = os.O_NOFOLLOW | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0)
    try:
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT | flags, new_file_mode())
            writable = True
        except PermissionError as denied:
            try:
                fd, writable = os.open(path, os.O_RDONLY | flags), False
            except FileNotFoundError:  # no lock file, and none may be made
                raise denied from None
    except OSError as exc:
        if os.path.islink(path) or os.path.isdir(path):  # O_NOFOLLOW's ELOOP; a directory's EISDIR
            raise not_regular(path, _mode(path), what, fix) from None
        raise type(exc)(f"--out: cannot create {str(path)!r}, the study's lock file: {exc.strerror}") from None
    try:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            raise not_regular(path, mode, what, fix)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise ValueError(f"study directory {d} is in use by {_holder(fd)}; wait for it or use another "
                             "--out") from None
        except OSError as exc:  # a file system without locks
            raise type(exc)(f"--out: cannot lock {str(path)!r} ({exc.strerror}); give an --out on a file system "
                            "with file locks") from None
        if writable:
            os.ftruncate(fd, 0)
            os.pwrite(fd, f"{os.getpid()} {socket.gethostname()}\n".encode(), 0)
        yield
    finally:
        os.close(fd)  # releases the lock


def _mode(path) -> int:
    """The mode of what ``path`` names, following symlinks; 0 for a dangling one."""
    try:
        return os.stat(path).st_mode
    except OSError:
        return 0


def _holder(fd: int) -> str:
    """Who holds a study's lock, as its lock file ``fd`` names it:
    ``process PID on HOST``, or ``another process`` when the file names no
    one, or names a process of this host that has ended: a holder that could
    only read the file (:func:`lock_study`) left an earlier run's name there,
    and the holder may not have written its own yet."""
    words = os.pread(fd, 512, 0).decode(errors="replace").split()
    if len(words) != 2 or not words[0].isdecimal() or int(words[0]) <= 0:
        return "another process"
    pid, host = int(words[0]), words[1]
    if host == socket.gethostname():
        try:
            os.kill(pid, 0)  # signal 0: only whether the process exists
        except (ProcessLookupError, OverflowError):
            return "another process"
        except PermissionError:  # it exists, another user's
            pass
    return f"process {pid} on {host}"


class Damaged(ValueError):
    """A study.json field that pyoa did not write (the message names it)."""


def _is_int(v, lo: int | None = None) -> bool:
    return isinstance(v, int) and not isinstance(v, bool) and (lo is None or v >= lo)


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and v >= 0


def _is_list(v, n: int, item) -> bool:
    return isinstance(v, list) and len(v) == n and all(map(item, v))


def _is_str(v) -> bool:
    return isinstance(v, str)


#: The fields of study.json as pyoa writes them: name -> (required, what it must be, check).
_SETTINGS = {
    "version": (True, "an integer", _is_int),
    "size": (True, "a list of 2 integers >= 1", lambda v: _is_list(v, 2, lambda x: _is_int(x, 1))),
    "crop": (True, "a list of 4 integers >= 0", lambda v: _is_list(v, 4, lambda x: _is_int(x, 0))),
    "max_depth": (True, "null or an integer >= 1", lambda v: v is None or _is_int(v, 1)),
    "filter": (True, "a string", _is_str),
    "shading": (True, "a string", _is_str),
    # absent in studies made before it was recorded: renderer version 1
    "renderer": (False, "an integer >= 1", lambda v: _is_int(v, 1)),
    "scenes": (True, "an object of scenes", lambda v: isinstance(v, dict)),
    "runs": (False, "a list of runs", lambda v: isinstance(v, list)),
}
#: Each of ``scenes``.
_SCENE = {
    "digest": (True, "a string", _is_str),
    "reference": (False, "null or a string", lambda v: v is None or _is_str(v)),
    "reference_name": (False, "a string", _is_str),
    "reference_spp": (False, "null or an integer >= 1", lambda v: v is None or _is_int(v, 1)),
    "reference_passes": (False, "null or an integer >= 1", lambda v: v is None or _is_int(v, 1)),
    "noise": (False, "null or a list of 2 numbers >= 0", lambda v: v is None or _is_list(v, 2, _is_number)),
}
#: Each of ``runs``.
_RUN = {
    "seconds": (True, "a number >= 0", _is_number),
    "rendered": (False, "an integer >= 0", lambda v: _is_int(v, 0)),
    "where": (False, "a string", _is_str),
    "date": (False, "a string", _is_str),
    "note": (False, "a string", _is_str),
}


def _check_fields(obj, fields: dict, where: str) -> None:
    """Raise :class:`Damaged` at the first field of ``obj`` (``where`` names
    it) that is missing or not what pyoa writes."""
    if not isinstance(obj, dict):
        raise Damaged(f"{where or 'its top level'} is not an object")
    for name, (required, what, test) in fields.items():
        if name not in obj:
            if required:
                raise Damaged(f"{where + ' ' if where else ''}has no {name!r}")
        elif not test(obj[name]):
            raise Damaged(f"{where + '.' if where else ''}{name} is {json.dumps(obj[name])[:40]}, not {what}")


#: Most bytes of a study.json: its settings and one record per scene and per
#: run, a few hundred bytes each, so far more than any study's.
MAX_SETTINGS_BYTES = 64 << 20


def load_settings(path: Path) -> dict | None:
    """A study's saved settings (``study.json``), checked field by field
    before anything uses them; None when there is none. A file that is not
    JSON, of another version, or with a field pyoa did not write is refused
    (ValueError naming the file and the field), before any render; so is
    one that is not a regular file (:func:`pyoa.render.state.open_regular`)
    or holds over :data:`MAX_SETTINGS_BYTES`."""
    from .render.state import open_regular

    if not path.exists():
        return None
    afresh = (f"the file is damaged: move it and {path.parent / 'study.csv'} away to start the study afresh, or "
              "give another --out")
    with open_regular(path, "the study's settings") as fh:
        data = fh.read(MAX_SETTINGS_BYTES + 1)
    if len(data) > MAX_SETTINGS_BYTES:
        raise ValueError(f"{path} holds over {MAX_SETTINGS_BYTES >> 20} MiB, not a study's settings; {afresh}")
    try:
        saved = json.loads(data)
    except ValueError as exc:
        raise ValueError(f"{path} is not a study's settings ({type(exc).__name__}); {afresh}") from None
    except RecursionError:  # the parser recurses once per nested list or object
        raise ValueError(f"{path} is not a study's settings (lists or objects nested too deeply); {afresh}") from None
    if isinstance(saved, dict) and _is_int(saved.get("version")) and saved["version"] != STUDY_VERSION:
        raise ValueError(f"{path} was written by another pyoa version; give another --out")
    try:
        _check_fields(saved, _SETTINGS, "")
        for name, scene in saved["scenes"].items():
            _check_fields(scene, _SCENE, f"scenes[{json.dumps(name)}]")
        for k, r in enumerate(saved.get("runs", [])):
            _check_fields(r, _RUN, f"runs[{k}]")
    except Damaged as exc:
        raise ValueError(f"{path}: {exc}; {afresh}") from None
    return saved


def check_settings(out: Path, saved: dict | None, settings: dict) -> dict:
    """The settings to save in ``study.json``: ``settings``, merged with the
    saved ones (:func:`load_settings`) when every setting both have agrees;
    otherwise a ValueError naming the first difference (rows of other
    settings are never mixed in). A scene's reference is checked apart
    (:func:`plan_references`)."""
    if saved is None:
        return settings
    if saved.get("renderer", 1) != settings["renderer"]:
        raise ValueError(f"{out} holds renders of pyoa's renderer version {saved.get('renderer', 1)}, and this pyoa "
                         f"renders with version {settings['renderer']}, whose images differ (see "
                         "pyoa.render.integrator.RENDERER_VERSION); give another --out to start a new study")
    for field in ("size", "crop", "max_depth", "filter", "shading"):
        if saved[field] != settings[field]:
            raise ValueError(f"{out} holds a study made with {field} {saved[field]}, not {settings[field]}; give "
                             "another --out to start a new study")
    scenes = dict(saved["scenes"])
    for name, s in settings["scenes"].items():
        old = scenes.get(name)
        if old is not None:
            if old["digest"] != s["digest"]:
                raise ValueError(f"{out} holds {name} renders made with other scene contents; give another --out")
            s = {**old, **{k: v for k, v in s.items() if v is not None}}
        scenes[name] = s
    return {**settings, "scenes": scenes, "runs": list(saved.get("runs", []))}


def write_settings(path: Path, settings: dict) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(settings, indent=1, sort_keys=True) + "\n")


def ident(row: dict) -> tuple:
    """What tells a row apart: (scene, sampler, spp asked, seed)."""
    return (row["scene"], row["sampler"], row["spp_asked"], row["seed"])


def _row(raw: dict) -> dict | None:
    """A CSV row with its types and the sampler's catalogue name, or None
    if it is not a complete row."""
    try:
        row = {"scene": raw["scene"], "sampler": raw["sampler"]}
        for k in ("spp_asked", "spp", "seed"):
            row[k] = int(raw[k])
        for k in ("relmse", "relmse_crop", "mse", "seconds"):
            row[k] = float(raw[k])
    except (KeyError, TypeError, ValueError):
        return None
    if not all(math.isfinite(row[k]) and row[k] >= 0 for k in ("relmse", "relmse_crop", "mse")):
        return None
    try:  # rows of pyoa before catalogue names (BOSE is bose), by the catalogue's own lookup
        row["sampler"] = canonical_sampler(row["sampler"])
    except ValueError:
        pass  # a sampler this pyoa does not have: kept as written (the report lists only the asked ones)
    return row


def _records(path: Path, text: str, damaged: str) -> list[tuple[int, list[str], bool]]:
    """The CSV records of ``text`` (study.csv's), each as ``(its first line,
    its fields, whether it is complete)``: a record is complete when its line
    break was written, so only the last can be incomplete (cut short, in a
    quoted field too). A record csv cannot read is refused (ValueError
    naming the file, the line and csv's reason, then ``damaged``)."""
    f = io.StringIO(text, newline="")
    reader = csv.reader(f, strict=True)  # strict: a quoted field cut at the end is an error, not a record
    records = []
    while True:
        number = reader.line_num + 1
        try:
            fields = next(reader)
        except StopIteration:
            return records
        except csv.Error as exc:
            if f.tell() == len(text) and str(exc) == "unexpected end of data":  # cut inside a quoted field
                return [*records, (number, [], False)]
            raise ValueError(f"{path}: line {number}: {exc}; {damaged}") from None
        records.append((number, fields, f.tell() < len(text) or text.endswith("\n")))


def read_rows(path: Path, repair: bool = False) -> list[dict]:
    """The complete rows of ``study.csv``, once each. A line cut short by an
    interruption is dropped; so is a second row of the same (scene, sampler,
    spp asked, seed) as an earlier one with the same measurements (two runs
    at once on one directory appended every row twice), while two such rows
    that disagree are refused. Sampler names are read as the catalogue
    spells them. With ``repair`` (the study's own run, holding the lock) the
    file is rewritten that way when it differs, saying so on stderr. A file
    that is not a study's CSV is refused, as is one that is not a regular
    file (:func:`pyoa.render.state.open_regular`) and a damaged one (not
    UTF-8, a field over the csv module's limit).

    The file is read as CSV, not line by line: a scene's name may hold a
    newline, a quote or a comma, which :class:`RowWriter` quotes."""
    from .render.state import open_regular

    if not path.exists():
        return []
    damaged = "the file is damaged: move it away (its rows are then rendered again), or give another --out"
    # read from the descriptor that was checked; newline="": quoted fields keep their line breaks (csv's rule)
    try:
        with io.TextIOWrapper(open_regular(path, "the study's rows"), encoding="utf-8", newline="") as fh:
            text = fh.read()
    except UnicodeDecodeError as exc:
        raise ValueError(f"{path} is not UTF-8 text ({exc.reason} at byte {exc.start}); {damaged}") from None
    records = _records(path, text, damaged)
    if not records:
        return []
    if records[0][1] != list(FIELDS):
        raise ValueError(f"{path} is not a pyoa study's CSV (its header is not {','.join(FIELDS)}); give another "
                         "--out")
    rows, first, dropped, renamed = [], {}, 0, 0
    cut = len(records) > 1 and not records[-1][2]  # the last row, cut short when the study was killed
    for number, fields, _ in records[1:len(records) - cut]:
        raw = dict(zip(FIELDS, fields)) if len(fields) == len(FIELDS) else None
        row = _row(raw) if raw else None
        if row is None:
            raise ValueError(f"{path}: line {number}: a row that is not a study's: {','.join(fields)[:200]!r}; "
                             "remove the file, or give another --out")
        renamed += row["sampler"] != raw["sampler"]
        seen = first.get(ident(row))
        if seen is not None:
            k, earlier = seen
            if any(earlier[f] != row[f] for f in ("spp", "relmse", "relmse_crop", "mse")):
                raise ValueError(f"{path}: lines {k} and {number} are two renders of {row['scene']} with "
                                 f"{row['sampler']} at {row['spp_asked']} spp, seed {row['seed']}, with different "
                                 "errors: renders of other settings were mixed in; give another --out")
            dropped += 1
            continue
        first[ident(row)] = (number, row)
        rows.append(row)
    if repair and (cut or dropped or renamed):
        buf = io.StringIO()
        write = _record_writer(buf)
        for r in rows:
            write(r)
        with atomic_path(path) as tmp:
            tmp.write_text(buf.getvalue(), encoding="utf-8")
        said = []  # a cut line goes without a word, as it always has
        if dropped:
            said.append(f"dropped {dropped} duplicate row{'s' * (dropped != 1)} (a scene, sampler, spp and seed "
                        "already there: each counts once)")
        if renamed:
            said.append(f"renamed the sampler of {renamed} row{'s' * (renamed != 1)} as the catalogue spells it")
        if said:
            print(f"pyoa study: {path}: {' and '.join(said)}; rewrote the file", file=sys.stderr)
    return rows


def _record_writer(fh, header: bool = True):
    """A function that writes a row to ``fh`` as one study.csv record (``\\n`` ends it), after the header
    unless ``header`` is False. A row holding a carriage return is written with every field quoted:
    before Python 3.12 the csv writer quotes a field for a line break only when the break is in its
    line terminator, so a scene named ``a\\rb`` was written bare, and read back as two records."""
    plain = csv.DictWriter(fh, fieldnames=FIELDS, lineterminator="\n")
    quoted = csv.DictWriter(fh, fieldnames=FIELDS, lineterminator="\n", quoting=csv.QUOTE_ALL)
    if header:
        plain.writeheader()

    def write(row: dict) -> None:
        record = {k: row[k] for k in FIELDS}
        (quoted if any("\r" in str(v) for v in record.values()) else plain).writerow(record)

    return write


class RowWriter:
    """Appends rows to ``study.csv``, one flushed CSV record each (UTF-8; a scene name holding a line break
    or a quote is quoted, as :func:`read_rows` reads it)."""

    def __init__(self, path: Path):
        new = not path.exists() or path.stat().st_size == 0
        self.fh = open(path, "a", newline="", encoding="utf-8")  # noqa: SIM115 - open for the whole study
        self.write = _record_writer(self.fh, header=new)
        if new:
            self.fh.flush()

    def add(self, row: dict) -> None:
        self.write(row)
        self.fh.flush()
        os.fsync(self.fh.fileno())

    def close(self) -> None:
        self.fh.close()


# -- tasks ---------------------------------------------------------------------------------------


def study_task(scene, reference: np.ndarray, crop, settings, job: Job, threads: int | None) -> dict:
    """One render of a study (``settings``, a
    :class:`~pyoa.render.settings.RenderSettings`, with the job's sampler,
    count and seed) and its errors against ``reference``: a CSV row."""
    from .render.image import check_finite, rel_mse
    from .render.tiles import worker_render

    res = worker_render(scene, settings.replace(sampler=job.sampler, spp=job.spp, seed=job.seed), threads=threads)
    check_finite(res.image, f"the {job.sampler} render of {job.scene} ({job.spp} spp, seed {job.seed})")
    diff = res.image.astype(np.float64) - reference
    return dict(scene=job.scene, sampler=job.sampler, spp_asked=job.spp_asked, spp=job.spp, seed=job.seed,
                relmse=rel_mse(res.image, reference), relmse_crop=rel_mse(res.image, reference, crop),
                mse=float(np.mean(diff * diff)), seconds=round(res.seconds, 4))


# -- statistics and the report -------------------------------------------------------------------


@dataclass
class Cell:
    """The statistics of one (scene, sampler, spp asked): over its seeds."""

    spp: int
    seeds: int
    values: np.ndarray  # measured relMSE per seed
    crop_values: np.ndarray
    noise: float  # the reference's noise estimate (0 when unknown)
    crop_noise: float

    def ci(self, crop: bool = False) -> tuple[float, float, float]:
        """(mean, low, high) of the noise-corrected relMSE."""
        m, lo, hi = mean_ci(self.crop_values if crop else self.values)
        n = self.crop_noise if crop else self.noise
        return corrected(m, n), corrected(lo, n), corrected(hi, n)


def cells(rows: list[dict], noise: dict) -> dict:
    """``{scene: {sampler: {spp_asked: Cell}}}`` of the rows; ``noise`` maps
    a scene to its reference's (image, crop) noise estimate or None."""
    groups: dict = {}
    for r in rows:
        groups.setdefault(r["scene"], {}).setdefault(r["sampler"], {}).setdefault(r["spp_asked"], []).append(r)
    out: dict = {}
    for scene, by_sampler in groups.items():
        nz = noise.get(scene) or (0.0, 0.0)
        for name, by_spp in by_sampler.items():
            for asked, rs in sorted(by_spp.items()):
                out.setdefault(scene, {}).setdefault(name, {})[asked] = Cell(
                    spp=rs[0]["spp"], seeds=len(rs), values=np.array([r["relmse"] for r in rs]),
                    crop_values=np.array([r["relmse_crop"] for r in rs]), noise=nz[0], crop_noise=nz[1])
    return out


def slope(by_spp: dict, crop: bool = False) -> float:
    """Fitted slope of log(corrected mean relMSE) against log spp (the positive means)."""
    n = [c.spp for c in by_spp.values()]
    v = [c.ci(crop)[0] for c in by_spp.values()]
    return fit_loglog(n, v)[0]


def _ratio(a: Cell, b: Cell) -> str:
    return format_ratio(*ratio_ci(a.values, b.values, shift_a=a.noise, shift_b=b.noise))


def headline(table: dict, labels: dict | None = None) -> list[str]:
    """Markdown: per scene and spp, bose / the best padded sampler (of those in ``table``) and bose / sobol
    (``labels``: the names shown, :func:`sampler_labels`)."""
    from .render.provenance import printable  # a scene name may hold a newline: one table row each

    labels = labels or {}
    lines = ["| scene | spp | best padded | bose / best padded | bose / sobol |", "|---|---:|---|---:|---:|"]
    any_row = False
    for scene, by_sampler in table.items():
        bose = by_sampler.get("bose", {})
        for asked, c in bose.items():
            padded = [(by_sampler[n][asked], n) for n in PADDED if asked in by_sampler.get(n, {})]
            best = min(padded, key=lambda cn: cn[0].ci()[0]) if padded else None
            sob = by_sampler.get("sobol", {}).get(asked)
            shown = f"{labels.get(best[1], best[1])} {best[0].spp}" if best else "-"
            lines.append(f"| {printable(scene)} | {c.spp} | {shown} | "
                         f"{_ratio(c, best[0]) if best else '-'} | {_ratio(c, sob) if sob else '-'} |")
            any_row = True
    return lines if any_row else []


def report(settings: dict, rows: list[dict], noise: dict, *, samplers=None, spp=None, seconds=None,
           where: str = "", labels: dict | None = None) -> str:
    """The Markdown report of a study (see the module docstring); ``seconds``
    the time of every run so far (``settings["runs"]``); ``labels`` the names its tables show
    (:func:`sampler_labels`; default: the catalogue's)."""
    from .render.provenance import printable
    from .render.reference import variance_path

    labels = labels or {}
    table = cells(rows, noise)
    n_runs = len(settings.get("runs", []))
    runs = f" ({n_runs} runs: the first and its resumptions)" if n_runs > 1 else ""
    w, h = settings["size"]
    x, y, cw, ch = settings["crop"]
    lines = ["# Sampler study", "",
             f"{len(rows)} renders at {w} x {h}, crop {cw} x {ch} at ({x}, {y}); relMSE = mean of "
             "(image - ref)^2 / (ref^2 + 0.01) (the paper's measure). Each cell: the mean over seeds of the relMSE "
             "minus the reference's own noise estimate where it is known (each scene's section says), ± the half-width of its 95 % Student-t interval over "
             "seeds. The slope is the least-squares fit of log(mean) against log(spp)." +
             (f" Rendered {where if where == 'in-process' else 'on ' + where}." if where else "") +
             (f" It took {seconds:.0f} s in all{runs}." if seconds is not None else ""), ""]
    for scene, by_sampler in table.items():
        s = settings["scenes"].get(scene, {})
        nz = noise.get(scene)
        ref = s.get("reference_name", "?")
        passes = s.get("reference_passes")
        # its header's count for a given image (header_passes); an image pyoa did not make has none
        whence = f"of its {passes} passes" if passes else f"in {variance_path(ref).name}"
        if nz is None:
            say = ("its own noise is unknown (no variance file beside it; references made with `pyoa reference` "
                   "have one), so the figures are not corrected")
        else:
            say = (f"its own noise adds an estimated {nz[0]:.2g} to every image relMSE and {nz[1]:.2g} to every "
                   f"crop relMSE (from the per-pixel variance {whence}); both are subtracted below")
        lines += [f"## {printable(scene)}", "", f"Reference `{printable(ref)}`: {say}.", ""]
        asked = sorted({a for by in by_sampler.values() for a in by})
        names = [n for n in (samplers or by_sampler) if n in by_sampler]
        for crop in (False, True):
            lines += [f"{'Crop' if crop else 'Image'} relMSE:", "",
                      "| sampler | " + " | ".join(f"{a} spp" for a in asked) + " | slope |",
                      "|---|" + "---:|" * (len(asked) + 1)]
            for n in names:
                by = by_sampler[n]
                cols = []
                for a in asked:
                    c = by.get(a)
                    if c is None:
                        cols.append("-")
                        continue
                    note = f" ({c.spp})" if c.spp != a else ""
                    cols.append(format_interval(*c.ci(crop)) + note)
                sl = slope(by, crop)
                shown = labels.get(n, n)
                lines.append(f"| {shown} | " + " | ".join(cols) + f" | {sl:.2f} |" if math.isfinite(sl) else
                             f"| {shown} | " + " | ".join(cols) + " | - |")
            lines.append("")
        seeds = sorted({c.seeds for by in by_sampler.values() for c in by.values()})
        lines += [f"Seeds per cell: {', '.join(map(str, seeds))}. A count in parentheses is the sampler's nearest "
                  "valid one, used instead of the column's.", ""]
    head = headline(table, labels)
    # the padded samplers this report holds: the best is chosen among those that ran, and only they are named
    padded = [n for n in PADDED if any(n in by for by in table.values())]
    if head:
        lines += ["## Headline", "",
                  "Ratios of noise-corrected mean image relMSE (below 1: bose is better), with 95 % intervals "
                  "over seeds (delta method on the log ratio with Student's t at Welch-Satterthwaite degrees of "
                  "freedom, which holds its level with 2 to 8 seeds; see pyoa.analysis.ratio_ci); " +
                  (f"the best padded sampler is the one of {', '.join(labels.get(n, n) for n in padded)} with the "
                   "lowest mean at that count." if padded else
                   f"no padded 2D sampler ({', '.join(PADDED)}) was run, so that column is empty."),
                  "", *head, ""]
    return "\n".join(lines)


def figure(table: dict, scenes: list[str], samplers: list[str]):
    """The study's figure (Matplotlib's Agg canvas): error against spp on log-log axes, one panel per
    scene, one line per sampler with its 95 % band, the x axis labelled with the counts asked for;
    None when no scene of ``scenes`` has rows. A band whose lower end is at or below 0 (the
    noise-corrected interval reaches 0) runs down to the panel's floor, a triangle there marks each
    such count, and the legend says so."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.ticker import FixedFormatter, FixedLocator, NullLocator

    scenes = [s for s in scenes if s in table]
    if not scenes:
        return None
    cols = min(len(scenes), 2)
    rows_ = -(-len(scenes) // cols)
    fig = Figure(figsize=(6.0 * cols, 4.6 * rows_), dpi=100, layout="constrained")
    FigureCanvasAgg(fig)
    # one colour per sampler, the same in every panel (tab10 repeats after 10)
    from matplotlib import colormaps

    colours = colormaps["tab20"].colors
    colour = {n: colours[(2 * k) % 20 + (2 * k) // 20 % 2] for k, n in enumerate(samplers)}
    for i, scene in enumerate(scenes):
        ax = fig.add_subplot(rows_, cols, i + 1)
        series = []
        for name in samplers:
            by = table[scene].get(name)
            if not by:
                continue
            pts = sorted((c.spp, *c.ci()) for c in by.values())
            n = np.array([p[0] for p in pts], dtype=float)
            m = np.array([p[1] for p in pts])
            lo = np.array([p[2] for p in pts])
            hi = np.array([p[3] for p in pts])
            keep = m > 0
            if not keep.any():
                continue
            sl = slope(by)
            (line,) = ax.loglog(n[keep], m[keep], marker="o", ms=3, lw=1.2, color=colour[name],
                                label=f"{name} ({sl:.2f})" if math.isfinite(sl) else name,
                                ls="-" if name not in PADDED else "--")
            series.append((line.get_color(), n, lo, hi, keep))
        # A lower end at or below 0 has no place on a log axis, and dropping its band hid that the interval
        # reaches 0: such a band runs down to the panel's floor (half a decade under its lowest positive
        # value), where a triangle marks the count and the legend says why.
        lows = [np.min(ln.get_ydata()) for ln in ax.get_lines()]  # the means drawn, all positive
        lows += [v for _, n, lo, hi, keep in series for v in lo[keep & (lo > 0)]]
        floor = min(lows, default=1.0) / 10 ** 0.5
        cut_any = 0
        for c, n, lo, hi, keep in series:
            band = keep & np.isfinite(lo) & np.isfinite(hi)
            if band.any():
                ax.fill_between(n[band], np.where(lo > 0, lo, floor)[band], hi[band], color=c, alpha=0.18, lw=0)
            cut = band & ~(lo > 0)
            if cut.any():
                # each sampler's triangles a step above the last one's: at one count they would hide each other
                at = floor * 10 ** (0.12 * cut_any)
                ax.plot(n[cut], np.full(cut.sum(), at), ls="none", marker="v", ms=6, color=c, clip_on=False)
                cut_any += 1
        if cut_any:
            ax.set_ylim(bottom=floor)
            ax.plot([], [], ls="none", marker="v", ms=6, color="0.4",
                    label="95 % interval reaches 0:\nband cut at the axis")
        # the counts asked for, as plain numbers (a log axis alone labels 2 x 10^1 and leaves the rest
        # blank); a sampler's nearest valid count is plotted where it is, unlabelled
        counts = sorted({asked for by in table[scene].values() for asked in by})
        ax.xaxis.set_major_locator(FixedLocator(counts))
        ax.xaxis.set_major_formatter(FixedFormatter([str(c) for c in counts]))
        ax.xaxis.set_minor_locator(NullLocator())
        ax.set_title(scene)
        ax.set_xlabel("samples per pixel")
        ax.set_ylabel("relMSE (reference noise removed)")
        ax.grid(True, which="both", lw=0.3, alpha=0.5)
        ax.legend(fontsize="x-small", title="sampler (slope)", title_fontsize="x-small")
    return fig


def plot(path, table: dict, scenes: list[str], samplers: list[str]) -> None:
    """Error against spp on log-log axes, one panel per scene, one line per
    sampler with its 95 % band (:func:`figure`), written atomically as a PNG."""
    fig = figure(table, scenes, samplers)
    if fig is None:
        return
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        fig.savefig(fh, format="png")


# -- the command ---------------------------------------------------------------------------------


@dataclass
class ReferencePlan:
    """What a study does for one scene's reference before its renders."""

    path: Path
    pixels: np.ndarray | None = None  # ready to use; None: render it first
    key: dict | None = None  # the reference's settings (pyoa.render.reference.reference_key) when rendered
    made_with: dict | None = None  # study.json's record of the settings that rendered it


def _in_passes(spp: int, passes: int) -> str:
    return f"{spp} spp in {passes} pass{'es' * (passes != 1)} of {spp // passes}"


def _made_with(saved: dict) -> str:
    """The reference a saved scene record names, as the user made it."""
    spp, passes = saved.get("reference_spp"), saved.get("reference_passes")
    if spp and passes:
        return f"a reference of {_in_passes(spp, passes)} (--reference-spp {spp} --pass-spp {spp // passes})"
    return f"the given reference {saved.get('reference_name', '?')}"


def header_passes(path) -> int | None:
    """The passes a reference's header records (``pyoa:passes``, :mod:`pyoa.render.provenance`), or
    None for an image that records none (one pyoa did not make, or a count that is not an int >= 1)."""
    from .render.image import read_attributes

    passes = read_attributes(path).get("passes")
    return passes if _is_int(passes, 1) else None


def _by_file(saved: dict) -> bool:
    """Whether a scene's record names its reference by the SHA-256 of its
    file's bytes (a study.json of pyoa before :func:`pixel_identity`)."""
    ref = saved.get("reference")
    return ref is not None and not ref.startswith(PIXELS)


def _unverifiable(out: Path, name: str, saved: dict, there: str, back: Path | None) -> str:
    """The refusal of a scene whose rows' reference is known by its file's
    bytes (:func:`_by_file`) when ``there`` (what was found) is not that
    file: nothing but that file can be checked against such an identity
    (the same pixels written again, as a reference rendered again is, make
    other bytes), so it is never taken on trust."""
    again = f" (or put it back at {back})" if back is not None else ""
    return (f"{out / 'study.json'} (of an older pyoa) knows the reference of its {name} rows, {_made_with(saved)}, "
            f"only by the SHA-256 of its file, and {there}: no other file can be checked against that, not even one "
            "of the same pixels (an EXR carries the time it was written, so a reference rendered again never "
            f"matches); give the original file with --reference{again}, or give another --out")


def _read_own(path: Path, saved: dict, dims) -> np.ndarray | None:
    """The pixels of the study's own reference file when study.json names
    it, else None (missing, unreadable, of another size or other pixels)."""
    from .render.image import read_reference

    if not path.is_file():
        return None
    try:
        pixels = read_reference(path, "the study's reference", *dims)
    except (OSError, ValueError):
        return None
    return pixels if is_reference(saved.get("reference"), path, pixels) else None


def plan_references(given: list[str] | None, reference_spp: int | None, out: Path, loaded: dict, settings: dict,
                    rows: list[dict], dims, rendering, pass_spp: int | None) -> dict:
    """Every scene's :class:`ReferencePlan`, checked before any work
    (``rendering``: the study's :class:`~pyoa.render.settings.RenderSettings`).

    A scene with rows keeps the reference they were measured against: a
    given image must have its pixels, and ``--reference-spp`` its settings
    (refused otherwise, before anything is written). A reference in DIR
    whose pixels study.json names, made with this run's settings, is used as
    it is; any other is rendered (resumed from its state) over it, which
    loses nothing: rows measured against the old one were refused above.
    ``given``: the reference images, one per scene in order (None: render
    them with ``reference_spp`` samples in passes of ``pass_spp``)."""
    from .render.image import EXR, check_output, read_reference
    from .render.reference import reference_key, variance_path
    from .render.render import check_job_memory, plan
    from .render.state import check_state_file, state_path

    measured = {r["scene"] for r in rows}
    plans = {}
    for i, (name, scene) in enumerate(loaded.items()):
        saved = settings["scenes"][name]
        if given:
            path = Path(given[i])
            # OpenImageIO would wait on a FIFO for ever, and read /dev/zero until memory runs out
            check_state_file(path, "--reference", "give the reference image itself")
            pixels = read_reference(path, "--reference", *dims)
            if name in measured and not is_reference(saved.get("reference"), path, pixels):
                if _by_file(saved):
                    raise ValueError(_unverifiable(out, name, saved, f"{path} is not that file", None))
                raise ValueError(f"{out} holds {name} renders measured against {_made_with(saved)}, not {path}; "
                                 "give that reference, or another --out")
            plans[name] = ReferencePlan(path, pixels)
            continue
        path = out / f"reference-{name}.exr"
        passes = reference_spp // pass_spp
        made_with = dict(reference_spp=reference_spp, reference_passes=passes)
        same = all(saved.get(k) == v for k, v in made_with.items())
        if name in measured and not same:
            raise ValueError(f"{out} holds {name} renders measured against {_made_with(saved)}, not one of "
                             f"{_in_passes(reference_spp, passes)}; give the reference they used, or another "
                             "--out")
        if name in measured and _by_file(saved):
            # rows measured against a file known only by its bytes: that file, or nothing (rendered again, it
            # would never match, so it is not rendered)
            pixels = _read_own(path, saved, dims)
            if pixels is None:
                there = f"{path} is {'missing' if not os.path.lexists(path) else 'not that file'}"
                raise ValueError(_unverifiable(out, name, saved, there, path))
            plans[name] = ReferencePlan(path, pixels, made_with=made_with)
            continue
        state = state_path(path)
        # a device or FIFO there would hang the read; refused now, not after the other scenes' references
        check_state_file(state, "where pyoa study keeps its running sum")
        if same and not state.exists():
            pixels = _read_own(path, saved, dims)
            if pixels is not None:
                plans[name] = ReferencePlan(path, pixels, made_with=made_with)
                continue
        # a reference to render: every output it writes, checked now
        check_output(path, "the study's reference", EXR)
        check_output(variance_path(path), "the study's reference variance", EXR)
        p = plan(scene, rendering, sampler="sobol", spp=pass_spp, seed=0)
        check_job_memory(p, f"a {name} reference pass of {pass_spp} spp")
        key = reference_key(scene, p, pass_spp=pass_spp, passes=passes, seed=0)
        plans[name] = ReferencePlan(path, None, key, made_with)
    return plans


@dataclass(frozen=True)
class StudySettings:
    """What a study computes and where it keeps it, as one immutable value (the study's counterpart of
    :class:`~pyoa.render.settings.RenderSettings`; ``pyoa study``'s options build it).

    Parameters
    ----------
    scenes : tuple of str
        Bundled scene names or scene files; a name given twice counts once.
    out : str or path
        The study's directory (study.csv, study.json, study.md, the figures, rendered references). A
        study whose directory holds rows continues it.
    samplers : str or sequence of str
        Sampler names (aliases allowed; ``"all"``: every sampler), as a sequence or comma-separated.
    spp : str or sequence of int
        Sample counts; a sampler without one uses its nearest valid count.
    seeds, seed : int
        Renders per (scene, sampler, count), with seeds ``seed, seed + 1, ...``.
    reference : sequence of str, optional
        The reference images, ``SCENE=FILE`` each (``FILE`` alone for one scene). Give these or
        ``reference_spp``.
    reference_spp, pass_spp : int, optional
        Render the references with ``reference_spp`` samples (sobol) in passes of ``pass_spp``.
    size : (int, int), optional
        Image size (default: the references', else the scenes').
    crop : (int, int, int, int), optional
        Crop window ``(x, y, w, h)`` of the cropped relMSE (default the quarter-size window at
        ``(W/4, H/4)``).
    max_depth, filter, backend, device, shading
        As :class:`~pyoa.render.settings.RenderSettings`.
    workers, scheduler
        The engine (:func:`pyoa.cluster.engine`): worker processes of a local cluster, or a
        scheduler's address; neither: in-process.
    quiet : bool
        Print nothing (the report is in ``out/study.md``).
    command : str, optional
        The command line recorded in rendered references' headers (:mod:`pyoa.render.provenance`).
    """

    scenes: tuple[str, ...]
    out: str | os.PathLike
    samplers: str | tuple[str, ...] = ",".join(catalogue.DEFAULT_SAMPLERS)
    spp: str | tuple[int, ...] = "16,64,256,1024"
    seeds: int = 8
    seed: int = 0
    reference: tuple[str, ...] | None = None
    reference_spp: int | None = None
    pass_spp: int = 256
    size: tuple[int, int] | None = None
    crop: tuple[int, int, int, int] | None = None
    max_depth: int | None = None
    filter: str = "box"
    backend: str | None = None
    device: str | None = None
    shading: str | None = None
    workers: int | None = None
    scheduler: str | None = None
    quiet: bool = False
    command: str | None = None

    def __post_init__(self):
        # sequences are kept as the comma-separated text the command line gives: the report's labels show the
        # names as typed, and the parsers (parse_spp, sampler_labels) check them in one place
        if not isinstance(self.samplers, str):
            object.__setattr__(self, "samplers", ",".join(map(str, self.samplers)))
        if not isinstance(self.spp, str):
            object.__setattr__(self, "spp", ",".join(map(str, self.spp)))
        object.__setattr__(self, "scenes", tuple(self.scenes))


def run_study(settings: StudySettings) -> int:
    """Run the study ``settings`` describes (``pyoa study``; see the module docstring), or continue it from
    what its directory holds. Returns 0; a refusal is a ValueError (or OSError) raised before any work."""
    from .cluster import check_engine, engine, progress_over
    from .render.image import check_crop, default_crop, read_reference
    from .render.integrator import RENDERER_VERSION
    from .render.provenance import describe
    from .render.reference import reference_noise, render_reference, variance_path
    from .render.render import check_job_memory, plan, resolve_shading
    from .render.scene import load
    from .render.scene_source import source_of
    from .render.settings import RenderSettings, check_seeds
    from .render.state import scene_digest

    t_start = time.perf_counter()
    scenes_arg = list(dict.fromkeys(settings.scenes))
    names = sampler_names(settings.samplers)
    spp_list = parse_spp(settings.spp)
    seed_list = check_seeds(settings.seed, settings.seeds)
    seeds, seed0 = len(seed_list), seed_list[0]
    if settings.max_depth is not None:
        from .render.layout import MAX_DEPTH

        check_int("--max-depth", settings.max_depth, 1, MAX_DEPTH)
    if settings.size is not None:
        for n, v in zip(("W", "H"), settings.size):
            check_int(f"--size {n}", v, 1)
    if settings.reference and settings.reference_spp is not None:
        raise ValueError("give --reference (existing images) or --reference-spp (render them), not both")
    if not settings.reference and settings.reference_spp is None:
        raise ValueError("a study needs references: --reference SCENE=REF.exr per scene (REF.exr alone for one "
                         "scene), or --reference-spp N to render them (pyoa reference, e.g. 16384)")
    given = reference_files(list(settings.reference) if settings.reference else None, scenes_arg)  # one per scene, in order
    size = list(settings.size) if settings.size is not None else None
    if given:
        # the references fix the size, as in pyoa compare; one of another size than --size (or than the
        # first reference) is refused before the study's directory is made
        from .render.image import check_reference, image_info
        from .render.state import check_state_file

        for path in given:
            # OpenImageIO would wait on a FIFO for ever, and read /dev/zero until memory runs out
            check_state_file(path, "--reference", "give the reference image itself")
        if size is None:
            size = list(image_info(given[0], "--reference")[:2])
        for path in given:
            check_reference(path, "--reference", *size)
    pass_spp = None
    if settings.reference_spp is not None:
        check_int("--reference-spp", settings.reference_spp, 1)
        pass_spp = check_int("--pass-spp", min(settings.pass_spp, settings.reference_spp), 1, MAX_SPP)
        if settings.reference_spp % pass_spp:
            raise ValueError(f"--reference-spp ({settings.reference_spp}) must be a multiple of --pass-spp ({pass_spp})")
    check_engine(settings.workers, settings.scheduler)
    out = check_out_dir(settings.out)
    with lock_study(out):
        # the saved study first: a damaged study.json or study.csv is refused before the scenes are loaded
        saved = load_settings(out / "study.json")
        rows = read_rows(out / "study.csv")
        shading = resolve_shading(settings.shading)
        film = dict(width=size[0], height=size[1]) if size else dict(width=None, height=None)
        # every render of the study, its references' passes included, with its sampler, count and seed
        rendering = RenderSettings(**film, max_depth=settings.max_depth, filter=settings.filter, backend=settings.backend,
                                   device=settings.device, shading=shading)
        # every check a long job could fail at its end, on the client, before any task
        loaded, jobs, dims = {}, [], None
        for sname in scenes_arg:
            scene = load(sname)
            if scene.name in loaded:
                raise ValueError(f"two scenes named {scene.name!r}; a study tells scenes apart by name")
            loaded[scene.name] = scene
            for name in names:
                for asked in spp_list:
                    n = catalogue.nearest_spp(name, asked)
                    if n is None:
                        raise ValueError(f"{name} has no valid sample count near {asked}")
                    p = plan(scene, rendering, sampler=name, spp=n, seed=seed0)
                    check_job_memory(p, f"a {scene.name} render with {name} at {n} spp")
                    if dims is None:
                        dims, first = (p.width, p.height), scene.name
                    elif (p.width, p.height) != dims:
                        raise ValueError(f"{first} renders {dims[0]} x {dims[1]} and {scene.name} "
                                         f"{p.width} x {p.height}; a study has one size: give --size W H")
                    jobs += [Job(scene.name, name, asked, n, seed0 + k) for k in range(seeds)]
        crop = tuple(settings.crop) if settings.crop else default_crop((dims[1], dims[0]))
        check_crop(crop, *dims)
        record = dict(version=STUDY_VERSION, renderer=RENDERER_VERSION, size=list(dims), crop=list(crop),
                        max_depth=settings.max_depth, filter=settings.filter, shading=shading,
                        scenes={n: dict(digest=scene_digest(s)) for n, s in loaded.items()})
        record = check_settings(out, saved, record)
        for r in rows:
            if r["scene"] in loaded and record["scenes"][r["scene"]].get("reference") is None:
                raise ValueError(f"{out / 'study.csv'} holds {r['scene']} rows but study.json no reference for "
                                 "them; give another --out")
        refs = plan_references(given, settings.reference_spp, out, loaded, record, rows, dims, rendering, pass_spp)
        # no file the study writes (study.csv is appended to) may be one it reads, by any link or spelling
        check_not_inputs([("--out", out / f) for f in ("study.csv", "study.json", "study.md", "study.png",
                                                       *(f"study-{n}.png" for n in loaded))],
                         [(f"{n}'s reference{v}", p) for n, r in refs.items()
                          for v, p in (("", r.path), (" variance", variance_path(r.path)))])
        # the variance files of the references at hand (a given one's too)
        noise = {n: reference_noise(r.path, r.pixels, crop) for n, r in refs.items() if r.pixels is not None}
        # every check made: now the rows the run appends to, as the catalogue spells them, once each
        rows = read_rows(out / "study.csv", repair=True)
        with engine(settings.workers, settings.scheduler) as eng:
            where = eng.description
            # references first (resumable passes on the same engine)
            images = {}
            for name, scene in loaded.items():
                ref, rec = refs[name], record["scenes"][name]
                if ref.pixels is None:
                    passes = ref.key["passes"]
                    if not settings.quiet:
                        print(f"reference of {name}: {settings.reference_spp} spp in {passes} passes on {where}")
                    one_pass = rendering.replace(sampler="sobol", spp=pass_spp, seed=0)
                    meta = describe(scene, plan(scene, one_pass), kind="reference",
                                    command=settings.command,
                                    passes=passes, pass_spp=pass_spp)
                    meta["spp"] = settings.reference_spp
                    render_reference(eng, scene, out=ref.path, key=ref.key, settings=one_pass, seed=0,
                                     quiet=settings.quiet, command="pyoa study", metadata=meta)
                    ref.pixels = read_reference(ref.path, "the study's reference", *dims)
                    if any(r["scene"] == name for r in rows) and not is_reference(rec.get("reference"), ref.path,
                                                                                   ref.pixels):
                        # the settings of its rows' reference, rendered again with other pixels (another pyoa)
                        raise ValueError(f"{out} holds {name} renders measured against another reference; give "
                                         "another --out (or the reference they used)")
                    noise[name] = reference_noise(ref.path, ref.pixels, crop)
                identity = pixel_identity(ref.pixels)
                if ref.made_with is not None:
                    rec.update(ref.made_with)
                elif not is_reference(rec.get("reference"), ref.path, ref.pixels):
                    # a given image, not one rendered here: its passes as its header records them
                    rec.update(reference_spp=None, reference_passes=header_passes(ref.path))
                elif rec.get("reference_passes") is None:  # recorded by a pyoa that did not read the header
                    rec.update(reference_passes=header_passes(ref.path))
                images[name] = ref.pixels.astype(np.float64)
                shown = ref.path.name if ref.path.resolve().parent == out.resolve() else str(ref.path)  # DIR's own
                rec.update(reference=identity, reference_name=shown,
                           noise=list(noise[name]) if noise[name] else None)
            write_settings(out / "study.json", record)
            done = {ident(r) for r in rows}
            todo = [j for j in jobs if j.ident not in done]
            if not settings.quiet:
                print(f"study: {len(jobs)} renders, {len(jobs) - len(todo)} already in {out / 'study.csv'}, "
                      f"{len(todo)} to render on {where}")
            shared = {n: (eng.share(s if eng.client is None else source_of(s)), eng.share(images[n]))
                      for n, s in loaded.items()}
            threads = eng.task_threads()
            args_list = [(*shared[j.scene], crop, rendering, j, threads) for j in todo]
            writer = RowWriter(out / "study.csv")
            try:
                with closing(eng.run(study_task, args_list, key="pyoa-study")) as results:
                    for _, row in progress_over(results, len(todo), "study", settings.quiet, unit="render"):
                        writer.add(row)
                        rows.append(row)
            finally:
                writer.close()
        seconds = time.perf_counter() - t_start
        # what each run (the first and every resumption) rendered, where, and how long it took
        record["runs"] = [*record.get("runs", []), dict(seconds=round(seconds, 1), where=where,
                                                            rendered=len(todo),
                                                            date=time.strftime("%Y-%m-%dT%H:%M:%S"))]
        write_settings(out / "study.json", record)
        wanted = {j.ident for j in jobs}
        mine = [r for r in rows if ident(r) in wanted]
        # the report follows the command's order of scenes and samplers, not the order rows were rendered in
        # (a resumed study appends the rows it renders after the ones it found)
        place = {(s, n): k for k, (s, n) in enumerate((s, n) for s in loaded for n in names)}
        mine.sort(key=lambda r: (place.get((r["scene"], r["sampler"]), len(place)), r["spp_asked"], r["seed"]))
        md = report(record, mine, noise, samplers=names, seconds=sum(r["seconds"] for r in record["runs"]),
                    where=where, labels=sampler_labels(settings.samplers))
        with atomic_path(out / "study.md") as tmp:
            tmp.write_text(md)
        table = cells(mine, noise)
        plot(out / "study.png", table, list(loaded), names)
        for name in loaded:
            plot(out / f"study-{name}.png", table, [name], names)
    if not settings.quiet:
        print(md)
        print(f"-> {out / 'study.md'}, {out / 'study.csv'}, {out / 'study.png'} ({seconds:.0f} s)")
    return 0


