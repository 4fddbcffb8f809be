"""pyoa's samplers inside Mitsuba 3: one sampler plugin, ``pyoa``.

Importing this module (or calling :func:`register`) registers the sampler
type ``pyoa`` with Mitsuba for the current variant and for every variant set
later, so a Mitsuba scene renders with any orthogonal array of pyoa, with
``faure``, ``zfaure`` or with ``random``::

    import mitsuba as mi
    import pyoa.mitsuba
    mi.set_variant("llvm_ad_rgb")
    scene = mi.load_dict(mi.cornell_box() | {"sensor": {..., "sampler": {
        "type": "pyoa", "sampler": "bose", "sample_count": 121}}})
    image = mi.render(scene)

or in a scene file::

    <sampler type="pyoa">
        <string name="sampler" value="bush"/>
        <integer name="sample_count" value="125"/>
        <integer name="strength" value="3"/>
        <string name="offset" value="cmj"/>
    </sampler>

Parameters
----------
sampler : str
    The pyoa sampler (default ``"bose"``): ``bose``, ``bush``, ``cmjnd``,
    ``addelman-kempthorne``, ``bose-bush``, ``faure``, ``zfaure`` (on the
    film's pixels, below) or ``random``
    (:data:`pyoa._drjit.SUPPORTED`; the other comparison samplers read
    tables and are left to Mitsuba's own samplers), in any case, or a
    Mitsuba/pbrt name of one of them (``orthogonal``, ``independent``:
    :data:`pyoa.catalogue.ALIASES`), as everywhere a sampler is named.
sample_count : int
    Samples per pixel, N (default 4). It must be a valid count of the
    sampler (``pyoa spp SAMPLER``); an invalid one fails when the scene loads
    with pyoa's own message naming the nearest valid counts. ``mi.render(...,
    spp=N)`` changes it the same way; a refused N leaves the sampler as it
    was (every check runs before any state changes).
seed : int
    Added by Mitsuba to the seed of each render (``mi.render(seed=...)``);
    the sum modulo ``2**32`` is pyoa's seed.
offset, jitter, strength, base, dims : str, float, int, int, int
    pyoa's options (:func:`pyoa.sampler`): the OA offset style (``cmj``,
    ``j``, ``mj``, ``centered``), the jitter amount in [0, 1], the strength
    t of ``bush``/``cmjnd``, ``faure``'s prime base (``zfaure``'s is fixed by
    its count ``b**m``), and the number of dimensions the integrator uses
    (only ``cmjnd`` and ``faure`` choose a default strength or base from it;
    0, the default, leaves it open).
samples_per_pass : int
    Only for an integrator that renders in passes (its own
    ``samples_per_pass``): the same value, a divisor of ``sample_count``.
    Default: one pass. Mitsuba tells a sampler its samples per pass through
    a non-virtual C++ method that a Python plugin never sees, so the plugin
    is told, and it reads the count Mitsuba set at every ``seed()``: a render
    whose samples per pass differ from the sampler's (the integrator's
    ``samples_per_pass`` without the same value here, a different value, or
    Mitsuba's own split of a pass over 2^32 samples) is refused there with
    a ValueError saying this, before any value is drawn, never rendered with
    a wrong mapping.

The mapping
-----------
Mitsuba renders a wavefront of ``P x n`` lanes, ``n = N / passes`` samples
per pass (``samples_per_pass`` above), pixel-major: lane ``l`` is pixel
``l // n`` and, in pass ``k`` (``advance()`` counts them), sample ``i = k n
+ l % n`` of that pixel, as in Mitsuba's own ``orthogonal`` and
``multijitter`` samplers (``Sampler::current_sample_index``). The ``d``-th
value drawn (``next_2d`` draws two, first x then y) is pyoa's x(pixel, i, d)
with the render's seed: exactly ``pyoa.sampler(name, spp=N, seed=S,
...).generate(pixels=range(P))[pixel, i, d]``. The pixel index counts the
film's pixels row by row, border included where the film samples one.
``clone()`` and ``fork()`` give samplers of the same parameters (fork
unseeded); neither changes the values: they depend only on (seed, pixel,
sample, dimension).

``zfaure`` hands one sequence out to the pixels along an order of the image,
so its pixel is the film's: pixel ``p`` of the window Mitsuba renders (the
film's crop, row by row) is the film's pixel ``(x, y) = (crop_x + p %
crop_width, crop_y + p // crop_width)``, and the values are exactly
``pyoa.sampler("zfaure", spp=N, seed=S, resolution=(width, height),
...).generate(pixels=[y * width + x])``: a crop renders the full image's
samples on its pixels. Mitsuba never tells a sampler its film, so at each
render's ``seed()`` the plugin finds the sensor being rendered among the
Python frames that called it (``mi.render`` and the Python integrators hold
it; a direct ``integrator.render(scene, sensor)`` is called with it) and
reads its film (:func:`_rendered_film`); a sampler seeded by hand is given
its film with ``set_film(film)``. Refused with a ValueError saying why: no
film found, a film whose window is not the wavefront's pixels, a film that
samples a border (``sample_border``: those lanes lie outside the image), and
an adjoint integrator (``ptracer``: its lanes are light paths, no pixels).

Values are computed with Dr.Jit operations (:mod:`pyoa._drjit`), traced into
Mitsuba's own kernels: no host round trip, so the sampler runs at Mitsuba's
speed. JIT variants (``llvm_*``, ``cuda_*``) only: loading the sampler in a
``scalar_*`` variant raises a ValueError saying so.
"""

from __future__ import annotations

import ctypes
import sys
from typing import NamedTuple

from .util.drjit_llvm import configure as _configure_llvm

_configure_llvm()  # before the LLVM backend starts (mi.set_variant('llvm_*')): see pyoa.util.drjit_llvm

try:
    import drjit as dr
    import mitsuba as mi
except ImportError as exc:  # pragma: no cover - exercised only without mitsuba
    raise ImportError("pyoa.mitsuba needs Mitsuba 3: pip install 'pyoa[mitsuba]'") from exc

from . import _drjit
from . import catalogue as _catalogue
from .catalogue.entries import MAX_DIMS, MAX_UINT32
from .samplers import sampler as _pyoa_sampler

#: Every option of the plugin, with its type as Mitsuba's Properties give it.
OPTIONS = {"sampler": str, "sample_count": int, "seed": int, "offset": str, "jitter": float,
           "strength": int, "base": int, "dims": int, "samples_per_pass": int}


def _props(props) -> dict:
    """The plugin's options from Mitsuba Properties, checked: unknown names and wrong types are refused."""
    out = {}
    for key in props.keys():  # noqa: SIM118 (Mitsuba Properties, not a dict)
        if key in ("id", "type"):
            continue
        if key not in OPTIONS:
            raise ValueError(f"pyoa sampler: unknown parameter {key!r}; valid: {', '.join(OPTIONS)}")
        value = props.get(key)
        want = OPTIONS[key]
        if want is float and isinstance(value, int) and not isinstance(value, bool):
            value = float(value)
        if not isinstance(value, want) or isinstance(value, bool):
            raise TypeError(f"pyoa sampler: {key} must be {'a string' if want is str else 'an ' + want.__name__ if want is int else 'a float'}"
                            f", got {type(value).__name__} {value!r}")
        out[key] = value
    return out


def _resolve(opts: dict, spp: int, resolution=None):
    """The pyoa Sampler of these options at ``spp`` (pyoa's own checks and messages).

    A sampler of an image (``zfaure``) takes ``resolution``, the film's size; before a film is
    known, ``(1, 1)`` checks every other parameter (the count and the base) with pyoa's messages."""
    name = opts.get("sampler", "bose")
    _drjit.implementation(name)  # ValueError naming the supported samplers
    dims = opts.get("dims", 0)
    if not 0 <= dims <= MAX_DIMS:
        raise ValueError(f"pyoa sampler: dims must be in [0, {MAX_DIMS}] (0: unknown), got {dims}")
    image = {"resolution": resolution or (1, 1)} if _catalogue.get(name).needs_resolution else {}
    return _pyoa_sampler(name, spp=spp, dims=dims or MAX_DIMS, seed=0, offset=opts.get("offset"),
                         jitter=opts.get("jitter", 1.0), strength=opts.get("strength"), base=opts.get("base"),
                         backend="numpy", **image)  # never used to generate: no OpenCL set-up


class _FilmGrid(NamedTuple):
    """Where Mitsuba's lanes lie on a film: the film's ``size`` (width, height) and the window it
    renders, ``crop_offset`` and ``crop_size`` (each (x, y)). Mitsuba's render loops give lane ``l``
    the pixel ``l // n`` of the window, row by row (``SamplingIntegrator::render``), which is pixel
    ``(x, y) = (crop_offset.x + p % crop_width, crop_offset.y + p // crop_width)`` of the film."""

    size: tuple[int, int]
    crop_offset: tuple[int, int]
    crop_size: tuple[int, int]

    @classmethod
    def of(cls, film) -> _FilmGrid:
        """The grid of a Mitsuba film; ValueError for a film whose lanes are not all its pixels."""
        if film.sample_border() and film.rfilter().border_size() > 0:
            raise ValueError(
                f"pyoa sampler: the film samples a border of {film.rfilter().border_size()} pixels around its "
                "image (hdrfilm sample_border=true): those lanes are no pixels of the image, so an image sampler "
                "(zfaure) has no place for them on its order; render with sample_border=false")
        return cls(*(tuple(int(v) for v in vec) for vec in (film.size(), film.crop_offset(), film.crop_size())))

    def pixels(self, lane_pixel):
        """The film's row-major pixel index (``y * width + x``) of window pixel ``lane_pixel``."""
        if self.crop_size == self.size:
            return lane_pixel
        y = lane_pixel // self.crop_size[0]
        x = lane_pixel - y * self.crop_size[0]
        return (y + self.crop_offset[1]) * self.size[0] + x + self.crop_offset[0]


def _rendered_film(smp) -> _FilmGrid | None:
    """The film that the render now seeding ``smp`` renders, or None when none is found.

    Mitsuba never tells a sampler its film (a sensor holds both; nothing links the sampler back),
    but every render loop is called with the sensor: ``mi.render``'s custom operation and the
    Python integrators' ``prepare`` hold it as a local variable, and a direct
    ``integrator.render(scene, sensor)`` is called from a frame holding the scene or the sensor.
    So the Python frames that led to this ``seed()`` are searched, innermost first, for a sensor
    whose sampler is ``smp`` or the sampler ``smp`` was cloned from (the Python integrators seed a
    clone); the innermost frame with one decides. A frame whose matching sensors have different
    films is refused: the lanes cannot be told apart.
    """
    mine = (smp, smp._origin)
    frame = sys._getframe(3)  # past this function, _film_for_seed() and seed()
    while frame is not None:
        values = list(frame.f_locals.values())
        sensors = [v for v in values if isinstance(v, mi.Sensor) and v.sampler() in mine]
        if not sensors:
            sensors = [s for v in values if isinstance(v, mi.Scene) for s in v.sensors() if s.sampler() in mine]
        if sensors:
            adjoint = [v for v in values if isinstance(v, mi.AdjointIntegrator)]
            if adjoint:
                raise ValueError(
                    f"pyoa sampler: {smp._pyoa.name} orders the film's pixels, but the integrator is an adjoint "
                    "one (mi.AdjointIntegrator: ptracer), which traces paths from the emitters: its lanes are no "
                    "pixels; use a sampler of single pixels (faure, bose, ...) with it")
            grids = {_FilmGrid.of(s.film()) for s in sensors}
            if len(grids) > 1:
                raise ValueError(f"pyoa sampler: the sampler is shared by sensors with different films "
                                 f"({sorted(grids)}); give each sensor its own sampler")
            return grids.pop()
        frame = frame.f_back
    return None


#: How many 32-bit words at the start of a sampler's C++ object :func:`_find_samples_per_wavefront`
#: reads: Mitsuba 3.9's ``Sampler`` members lie within the first 18 (``m_samples_per_wavefront`` is
#: word 14 on x86-64 Linux), and a Python sampler's C++ object is 240 bytes (nanobind's trampoline
#: table follows the members; Mitsuba 3.9.1, llvm_ad_rgb), so every word read belongs to the object.
_PROBE_WORDS = 32


def _find_samples_per_wavefront(smp, base: type) -> int:
    """The byte offset of Mitsuba's ``Sampler::m_samples_per_wavefront`` in ``smp``'s C++ object.

    Mitsuba's render loop tells the sampler its samples per pixel per pass with
    ``Sampler::set_samples_per_wavefront``, a non-virtual C++ method: it never reaches a sampler
    written in Python, and the value it stores has no getter. The plugin reads it at every
    ``seed()`` (the only way to know how Mitsuba splits the wavefront into pixels), at the offset
    found here, once per class: the method, called through ``base`` (``mi.Sampler``) with three
    values, must change exactly one 32-bit word of the object to those values. ``smp`` must be
    freshly constructed (Mitsuba's default base sample_count, 4, which the values divide).

    Raises
    ------
    RuntimeError
        When no single word follows the values (a Mitsuba build with another layout).
    """
    words = (ctypes.c_uint32 * _PROBE_WORDS).from_address(smp.ptr)
    probes = (4, 2, 1)
    seen = []
    for value in probes:
        base.set_samples_per_wavefront(smp, value)
        seen.append(list(words))
    hits = [k for k in range(_PROBE_WORDS) if tuple(w[k] for w in seen) == probes]
    if len(hits) != 1:
        raise RuntimeError(f"pyoa.mitsuba: cannot find a sampler's samples per pass in this Mitsuba build "
                           f"({mi.__version__}; found {len(hits)} candidates): pyoa.mitsuba supports Mitsuba 3.9.x")
    return 4 * hits[0]


def _make_class(base: type) -> type:
    """The plugin's class on ``base``, one Mitsuba variant's ``mi.Sampler``."""

    class PyoaSampler(base):
        """A pyoa sampler as a Mitsuba sampler (the module docstring is its user doc).

        Built by :func:`sampler_class` on the current variant's ``mi.Sampler``
        (each variant has its own base class, and nanobind classes take one base).
        """

        def __init__(self, props=None):
            opts = props if isinstance(props, dict) else _props(mi.Properties() if props is None else props)
            super().__init__(mi.Properties())
            self._opts = dict(opts)
            self._origin = None  # the sampler this one was cloned from (_rendered_film)
            self._film = None  # the _FilmGrid given by set_film(), for a sampler seeded outside a render
            self._pyoa = None
            self._base_seed = self._opts.get("seed", 0)
            if not 0 <= self._base_seed <= MAX_UINT32:
                raise ValueError(f"pyoa sampler: seed must be a uint32 in [0, {MAX_UINT32}], got {self._base_seed}")
            if PyoaSampler._spw_offset is None:  # once per class, on a fresh object (see the function)
                PyoaSampler._spw_offset = _find_samples_per_wavefront(self, base)
            self._configure(self._opts.get("sample_count", 4))
            self._unseed()

        #: byte offset of Mitsuba's m_samples_per_wavefront in the C++ object (_find_samples_per_wavefront)
        _spw_offset = None

        # -- parameters -------------------------------------------------------------------------------

        def _configure(self, spp: int) -> None:
            """Make ``spp`` the sample count: every check runs before any state changes, so a refused
            count (``mi.render(scene, spp=N)``) leaves the sampler exactly as it was."""
            # an image sampler keeps the film of its last seed(): a count refused for it is refused here
            pyoa_sampler = _resolve(self._opts, spp, self._pyoa.resolution if self._pyoa else None)
            per_pass = self._opts.get("samples_per_pass", 0) or spp
            if per_pass < 1 or spp % per_pass:
                raise ValueError(f"pyoa sampler: samples_per_pass ({per_pass}) must divide sample_count ({spp}); "
                                 "give a sample count (mi.render(spp=...)) that is a multiple of samples_per_pass")
            self._pyoa, self._spp = pyoa_sampler, spp
            # the samples per pass this sampler maps lanes with: sample_count, or samples_per_pass when
            # given here (the integrator's, which must then be the same); seed() checks it against the
            # count Mitsuba's render loop set in the C++ base, which starts out equal to it
            self._spw = per_pass
            super().set_sample_count(spp)
            super().set_samples_per_wavefront(per_pass)

        def set_sample_count(self, spp: int) -> None:
            self._configure(int(spp))

        def sample_count(self) -> int:
            return self._spp

        def set_samples_per_wavefront(self, samples_per_wavefront: int) -> None:
            # reached from Python only (Mitsuba's Python integrators, tests): the C++ render loop calls
            # the base method directly, which seed() reads back (_mitsuba_samples_per_wavefront)
            n = int(samples_per_wavefront)
            if n < 1 or self._spp % n:
                raise ValueError(f"pyoa sampler: samples per wavefront ({n}) must divide sample_count ({self._spp})")
            self._spw = n
            super().set_samples_per_wavefront(n)

        def _mitsuba_samples_per_wavefront(self) -> int:
            """The samples per pixel per pass Mitsuba last set (``Sampler::m_samples_per_wavefront``)."""
            return ctypes.c_uint32.from_address(self.ptr + PyoaSampler._spw_offset).value

        @property
        def pyoa_sampler(self):
            """The :class:`pyoa.samplers.Sampler` whose values this plugin draws (seed 0; Mitsuba sets the seed).

            For an image sampler (``zfaure``) its resolution is the film's since the last ``seed()``
            ((1, 1) before one)."""
            return self._pyoa

        def set_film(self, film) -> None:
            """The film whose pixels this sampler's lanes are, for an image sampler (``zfaure``) seeded
            outside a render (a render finds its film itself, :func:`_rendered_film`): a ``mi.Film``
            (``mi.load_dict({"type": "hdrfilm", "width": W, "height": H})``). Checked like a render's."""
            self._film = _FilmGrid.of(film)

        # -- state --------------------------------------------------------------------------------------

        def _unseed(self) -> None:
            self.m_dimension = mi.UInt32(0)
            self.m_pass = mi.UInt32(0)
            self._passes = 0  # m_pass on the host, to refuse samples past sample_count
            self._seed_args = None
            self._lane_sample = None
            self._forget_block()

        def _forget_block(self) -> None:
            """No block located yet in this pass (see :meth:`_located`): the next draw locates its own."""
            self._block = dr.opaque(mi.UInt32, _NO_BLOCK)
            self._block_seed = self._block_row = mi.UInt32(0)

        def seed(self, seed, wavefront_size=MAX_UINT32) -> None:
            # Mitsuba's lanes are pixels of `per_pass` samples (the count its render loop set just before
            # seeding); this sampler's mapping holds only when that is its own count. Checked before
            # anything changes, so a refused render leaves the sampler as it was.
            n = int(wavefront_size)
            if n == MAX_UINT32:  # Mitsuba's "unspecified": the wavefront of the previous seed
                n = self.wavefront_size()
                if n == 0:
                    raise ValueError("pyoa sampler: the first seed() needs the wavefront size (lanes)")
            per_pass = self._mitsuba_samples_per_wavefront()
            whole = n >= per_pass  # (fewer: the 1-lane seed Mitsuba gives after a render to release memory)
            if whole:
                self._check_wavefront(n, per_pass)
            entry = self._pyoa._construction
            grid = self._film_for_seed(n // per_pass) if whole and entry.needs_resolution else None
            pyoa_sampler = self._pyoa
            if grid and grid.size != pyoa_sampler.resolution:
                pyoa_sampler = _resolve(self._opts, self._spp, grid.size)
            super().seed(seed, wavefront_size)
            self._pyoa = pyoa_sampler
            lane = dr.arange(mi.UInt32, n)
            s = mi.UInt32(seed) + self._base_seed if dr.is_array_v(seed) else mi.UInt32((int(seed) + self._base_seed) % 2**32)
            # opaque, as Mitsuba's own samplers make theirs: a literal seed would be baked into the traced
            # kernel, and every new seed would compile a new one (measured: 0.35 s per render for bose)
            dr.make_opaque(s)
            pixel = lane // self._spw
            # the catalogue's seed arguments, once per seed: the pixel's point-set seed, or (an image
            # sampler, which has drawable lanes only with a film) the film's pixel and the seed
            if not entry.needs_resolution:
                self._seed_args = entry.seed_args(_drjit.hashes.pixel_seed, s, pixel)
            else:
                self._seed_args = entry.seed_args(_drjit.hashes.pixel_seed, s, grid.pixels(pixel)) if grid else None
            self._lane_sample = lane % self._spw
            # opaque, as Mitsuba's own counters: one kernel serves every pass
            self.m_dimension = dr.opaque(mi.UInt32, 0)
            self.m_pass = dr.opaque(mi.UInt32, 0)
            self._passes = 0
            self._forget_block()

        def _film_for_seed(self, pixels: int) -> _FilmGrid:
            """The film an image sampler's ``pixels`` lanes of whole pixels lie on: the film of the render
            seeding it, else the one given to :meth:`set_film`; ValueError when there is none, or when its
            window (the crop) is not ``pixels`` pixels."""
            grid = _rendered_film(self) or self._film
            name = self._pyoa.name
            if grid is None:
                raise ValueError(
                    f"pyoa sampler: {name} orders the film's pixels, and no film was found for this seed(): render "
                    "with mi.render(scene) or integrator.render(scene, sensor), or call sampler.set_film(film) "
                    "before seeding the sampler yourself")
            (w, h), (cw, ch) = grid.size, grid.crop_size
            if cw * ch != pixels:
                raise ValueError(f"pyoa sampler: {name} was seeded with {pixels} pixels of lanes, but the film "
                                 f"renders {cw} x {ch} pixels{f' (a crop of {w} x {h})' if (cw, ch) != (w, h) else ''}"
                                 ": the lanes are not the film's pixels")
            return grid

        def _check_wavefront(self, n: int, per_pass: int) -> None:
            """Refuse a wavefront of ``n`` lanes that Mitsuba splits into pixels of ``per_pass`` samples
            unless this sampler maps its lanes the same way (the documented mapping)."""
            if per_pass != self._spw:
                mine = (f"one pass of its sample_count {self._spp}" if self._spw == self._spp
                        else f"passes of {self._spw} (samples_per_pass)")
                raise ValueError(
                    f"pyoa sampler: Mitsuba renders {per_pass} samples per pixel per pass here (the integrator's "
                    f"samples_per_pass, or fewer when one pass would exceed 2^32 samples), but this sampler is set "
                    f"up for {mine}: give the pyoa sampler and the integrator the same samples_per_pass, a divisor "
                    f"of sample_count {self._spp} (<integer name=\"samples_per_pass\" .../> in both), or neither")
            if n % per_pass:
                raise ValueError(f"pyoa sampler: a wavefront of {n} lanes is not whole pixels of {per_pass} samples")

        def advance(self) -> None:
            # not super().advance(): through nanobind's trampoline it calls this method again
            self.m_dimension = dr.opaque(mi.UInt32, 0)
            self.m_pass = self.m_pass + 1
            self._passes += 1
            self._forget_block()  # a new pass: new sample indices, so new rows

        def schedule_state(self) -> None:
            dr.schedule(self.m_dimension, self.m_pass, self._block, self._block_seed, self._block_row)

        def clone(self):
            other = type(self)(dict(self._opts, sample_count=self._spp))
            other.set_samples_per_wavefront(self._spw)
            other._origin, other._film, other._pyoa = self._origin or self, self._film, self._pyoa
            other._seed_args, other._lane_sample = self._seed_args, self._lane_sample
            other.m_dimension, other.m_pass = mi.UInt32(self.m_dimension), mi.UInt32(self.m_pass)
            other._passes = self._passes
            other._block, other._block_seed, other._block_row = (mi.UInt32(x) for x in (
                self._block, self._block_seed, self._block_row))
            return other

        def fork(self):
            other = self.clone()
            other._unseed()
            return other

        # -- values -------------------------------------------------------------------------------------

        def next_1d(self, active=True):
            if self._seed_args is None:
                on_film = " (with whole pixels of lanes on a film)" if self._pyoa._construction.needs_resolution else ""
                raise RuntimeError(f"pyoa sampler: seed() the sampler before drawing values{on_film}")
            if self._passes * self._spw >= self._spp:
                raise RuntimeError(f"pyoa sampler: pass {self._passes} of {self._spw} samples is past sample_count "
                                   f"{self._spp} (advance() was called {self._passes} times since seed())")
            smp = self._pyoa
            entry = smp._construction
            i = self.m_pass * self._spw + self._lane_sample
            j = mi.UInt32(self.m_dimension)
            f = _drjit.implementation(entry.name)
            args = (i, j, *entry.shape_args(smp.params), *self._seed_args, *entry.options(smp.offset, smp.jitter))
            x = f(*args, located=self._located(i, j)) if entry.drjit_located else f(*args)
            self.m_dimension += 1
            return mi.Float(x)

        def _located(self, i, j) -> tuple:
            """``(P, row)`` of dimension ``j``'s block for every lane (docs/spec.md section 6), kept in
            the sampler's state: a draw that enters a new block computes them, the block's other draws
            reuse them, so a value costs its cell and tail only, not the block's hashes and two row
            permutations. The dimension is the same in every lane (Mitsuba draws it for the whole
            wavefront), so the loop below runs for all lanes or none: inside Mitsuba's symbolic loops
            Dr.Jit skips its body on every draw that stays in the block."""
            prm = self._pyoa.params
            N, block = prm.N, j // prm.B
            (p,) = self._seed_args

            def locate(P, row, todo):
                P, row = _drjit.hashes.locate_block(p, i, block, N)
                return P, row, todo & False

            todo = dr.full(mi.Bool, True, dr.width(i)) & (block != self._block)
            P, row, _ = dr.while_loop(state=(self._block_seed, self._block_row, todo),
                                      cond=lambda P, row, todo: todo, body=locate, label="pyoa_locate_block")
            self._block_seed, self._block_row, self._block = P, row, block
            return P, row

        def next_2d(self, active=True):
            x = self.next_1d(active)
            y = self.next_1d(active)
            return mi.Point2f(x, y)

        def to_string(self) -> str:
            smp = self._pyoa
            detail = smp._construction.choice(smp.params).shape()
            opts = ", ".join(f"{k}={v!r}" for k, v in self._opts.items() if k not in ("sampler", "sample_count"))
            return (f"PyoaSampler[{smp.name}, sample_count={self._spp}{', ' + opts if opts else ''}"
                    f"{' (' + detail + ')' if detail else ''}, samples per wavefront {self._spw}]")

        def __repr__(self) -> str:
            return self.to_string()

    return PyoaSampler


def _refuse_scalar(variant: str):
    def make(props):
        raise ValueError(f"the pyoa sampler needs a JIT variant of Mitsuba (llvm_* or cuda_*), got {variant}: "
                         "its values are traced into Mitsuba's kernels; mi.set_variant('llvm_ad_rgb') for the CPU")
    return make


def _register_current(*_args) -> None:
    variant = mi.variant()
    if variant is None:
        return
    if variant.startswith("scalar_"):
        mi.register_sampler("pyoa", _refuse_scalar(variant))
    else:
        cls = sampler_class()
        mi.register_sampler("pyoa", lambda props: cls(props))


def sampler_class() -> type:
    """The plugin's class for the current Mitsuba variant (``mi.Sampler`` differs per variant)."""
    variant = mi.variant()
    if variant is None:
        raise RuntimeError("set a Mitsuba variant first, e.g. mi.set_variant('llvm_ad_rgb')")
    cls = _CLASSES.get(variant)
    if cls is None:
        cls = _CLASSES[variant] = _make_class(mi.Sampler)
    return cls


#: The block number of "no block located yet" (:meth:`PyoaSampler._located`): no dimension's block is
#: this large (block = dimension // B, and dimensions are counted in a uint32).
_NO_BLOCK = 0xFFFFFFFF

_CLASSES: dict[str, type] = {}
_REGISTERED = False


def register() -> None:
    """Register the ``pyoa`` sampler type for the current Mitsuba variant and every one set later
    (idempotent; importing this module calls it)."""
    global _REGISTERED
    _register_current()
    if not _REGISTERED:
        mi.detail.add_variant_callback(_register_current)
        _REGISTERED = True


register()
