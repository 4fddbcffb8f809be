"""pyoa's samplers inside Mitsuba 3: one sampler plugin, ``pyoa``.

Importing this module (or calling :func:`register`) registers the sampler
type ``pyoa`` with Mitsuba for the current variant and for every variant set
later, so a Mitsuba scene renders with any orthogonal array of pyoa, with
``faure`` or with ``random``::

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
    ``addelman-kempthorne``, ``bose-bush``, ``faure`` or ``random``
    (:data:`pyoa._drjit.SUPPORTED`; the other comparison samplers read
    tables and are left to Mitsuba's own samplers).
sample_count : int
    Samples per pixel, N (default 4). It must be a valid count of the
    sampler (``pyoa spp SAMPLER``); an invalid one fails when the scene loads
    with pyoa's own message naming the nearest valid counts. ``mi.render(...,
    spp=N)`` changes it the same way.
seed : int
    Added by Mitsuba to the seed of each render (``mi.render(seed=...)``);
    the sum modulo ``2**32`` is pyoa's seed.
offset, jitter, strength, base, dims : str, float, int, int, int
    pyoa's options (:func:`pyoa.sampler`): the OA offset style (``cmj``,
    ``j``, ``mj``, ``centered``), the jitter amount in [0, 1], the strength
    t of ``bush``/``cmjnd``, ``faure``'s prime base, and the number of
    dimensions the integrator uses (only ``cmjnd`` and ``faure`` choose a
    default strength or base from it; 0, the default, leaves it open).
samples_per_pass : int
    Only for an integrator that renders in passes (its own
    ``samples_per_pass``): the same value, a divisor of ``sample_count``.
    Mitsuba tells a sampler its samples per pass through a C++ method that
    a Python plugin cannot see, so the plugin must be told; without it a
    render in passes fails at its second pass (``advance()``) with a message
    saying this, never with a wrong image. Default: one pass.

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

Values are computed with Dr.Jit operations (:mod:`pyoa._drjit`), traced into
Mitsuba's own kernels: no host round trip, so the sampler runs at Mitsuba's
speed. JIT variants (``llvm_*``, ``cuda_*``) only: loading the sampler in a
``scalar_*`` variant raises a ValueError saying so.
"""

from __future__ import annotations

from .drjit_llvm import configure as _configure_llvm

_configure_llvm()  # before the LLVM backend starts (mi.set_variant('llvm_*')): see pyoa.drjit_llvm

try:
    import drjit as dr
    import mitsuba as mi
except ImportError as exc:  # pragma: no cover - exercised only without mitsuba
    raise ImportError("pyoa.mitsuba needs Mitsuba 3: pip install 'pyoa[mitsuba]'") from exc

from . import _drjit
from .catalogue_types import MAX_DIMS, MAX_UINT32
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


def _resolve(opts: dict, spp: int):
    """The pyoa Sampler of these options at ``spp`` (pyoa's own checks and messages)."""
    name = opts.get("sampler", "bose")
    _drjit.implementation(name)  # ValueError naming the supported samplers
    dims = opts.get("dims", 0)
    if not 0 <= dims <= MAX_DIMS:
        raise ValueError(f"pyoa sampler: dims must be in [0, {MAX_DIMS}] (0: unknown), got {dims}")
    return _pyoa_sampler(name, spp=spp, dims=dims or MAX_DIMS, seed=0, offset=opts.get("offset"),
                         jitter=opts.get("jitter", 1.0), strength=opts.get("strength"), base=opts.get("base"),
                         backend="numpy")  # never used to generate: no OpenCL set-up


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
            self._base_seed = self._opts.get("seed", 0)
            if not 0 <= self._base_seed <= MAX_UINT32:
                raise ValueError(f"pyoa sampler: seed must be a uint32 in [0, {MAX_UINT32}], got {self._base_seed}")
            self._configure(self._opts.get("sample_count", 4))
            self._unseed()

        # -- parameters -------------------------------------------------------------------------------

        def _configure(self, spp: int) -> None:
            self._pyoa = _resolve(self._opts, spp)
            per_pass = self._opts.get("samples_per_pass", 0) or spp
            if per_pass < 1 or spp % per_pass:
                raise ValueError(f"pyoa sampler: samples_per_pass ({per_pass}) must divide sample_count ({spp})")
            self._spp = spp
            # Mitsuba's own render loop sets the samples per wavefront through a non-virtual C++ method
            # that never reaches this class: it is sample_count, or samples_per_pass when given here
            # (the integrator's samples_per_pass, which must then be the same)
            self._spw = per_pass
            super().set_sample_count(spp)

        def set_sample_count(self, spp: int) -> None:
            self._configure(int(spp))

        def sample_count(self) -> int:
            return self._spp

        def set_samples_per_wavefront(self, samples_per_wavefront: int) -> None:
            n = int(samples_per_wavefront)  # reached from Python only (see _configure)
            if n < 1 or self._spp % n:
                raise ValueError(f"pyoa sampler: samples per wavefront ({n}) must divide sample_count ({self._spp})")
            self._spw = n
            super().set_samples_per_wavefront(n)

        @property
        def pyoa_sampler(self):
            """The :class:`pyoa.samplers.Sampler` whose values this plugin draws (seed 0; Mitsuba sets the seed)."""
            return self._pyoa

        # -- state --------------------------------------------------------------------------------------

        def _unseed(self) -> None:
            self.m_dimension = mi.UInt32(0)
            self.m_pass = mi.UInt32(0)
            self._passes = 0  # m_pass on the host, to refuse samples past sample_count
            self._pixel_seed = None
            self._lane_sample = None

        def seed(self, seed, wavefront_size=MAX_UINT32) -> None:
            super().seed(seed, wavefront_size)
            n = int(wavefront_size)
            if n >= self._spw and n % self._spw:  # (Mitsuba seeds 1 lane to release memory after a render)
                raise ValueError(f"pyoa sampler: a wavefront of {n} lanes is not whole pixels of {self._spw} samples: "
                                 "Mitsuba renders in passes here (the integrator's samples_per_pass, or more than "
                                 "2^32 samples); give the pyoa sampler the same samples_per_pass")
            lane = dr.arange(mi.UInt32, n)
            s = mi.UInt32(seed) + self._base_seed if dr.is_array_v(seed) else mi.UInt32((int(seed) + self._base_seed) % 2**32)
            # opaque, as Mitsuba's own samplers make theirs: a literal seed would be baked into the traced
            # kernel, and every new seed would compile a new one (measured: 0.35 s per render for bose)
            dr.make_opaque(s)
            self._pixel_seed = _drjit.hashes.pixel_seed(s, lane // self._spw)
            self._lane_sample = lane % self._spw
            # opaque, as Mitsuba's own counters: one kernel serves every pass
            self.m_dimension = dr.opaque(mi.UInt32, 0)
            self.m_pass = dr.opaque(mi.UInt32, 0)
            self._passes = 0

        def advance(self) -> None:
            # not super().advance(): through nanobind's trampoline it calls this method again
            if self._spw == self._spp:
                raise RuntimeError(
                    f"pyoa sampler: Mitsuba renders in passes (advance() was called), but this sampler was set up "
                    f"for one pass of {self._spp} samples: give it the integrator's samples_per_pass "
                    "(<integer name=\"samples_per_pass\" .../> in both), or render in one pass")
            self.m_dimension = dr.opaque(mi.UInt32, 0)
            self.m_pass = self.m_pass + 1
            self._passes += 1

        def schedule_state(self) -> None:
            dr.schedule(self.m_dimension, self.m_pass)

        def clone(self):
            other = type(self)(dict(self._opts, sample_count=self._spp))
            other.set_samples_per_wavefront(self._spw)
            other._pixel_seed, other._lane_sample = self._pixel_seed, self._lane_sample
            other.m_dimension, other.m_pass = mi.UInt32(self.m_dimension), mi.UInt32(self.m_pass)
            other._passes = self._passes
            return other

        def fork(self):
            other = self.clone()
            other._unseed()
            return other

        # -- values -------------------------------------------------------------------------------------

        def next_1d(self, active=True):
            if self._pixel_seed is None:
                raise RuntimeError("pyoa sampler: seed() the sampler before drawing values")
            if self._passes * self._spw >= self._spp:
                raise RuntimeError(f"pyoa sampler: pass {self._passes} of {self._spw} samples is past sample_count "
                                   f"{self._spp} (advance() was called {self._passes} times since seed())")
            smp = self._pyoa
            entry = smp._construction
            i = self.m_pass * self._spw + self._lane_sample
            f = _drjit.implementation(entry.name)
            x = f(i, mi.UInt32(self.m_dimension), *entry.shape_args(smp.params), self._pixel_seed,
                  *entry.options(smp.offset, smp.jitter))
            self.m_dimension += 1
            return mi.Float(x)

        def next_2d(self, active=True):
            x = self.next_1d(active)
            y = self.next_1d(active)
            return mi.Point2f(x, y)

        def to_string(self) -> str:
            smp = self._pyoa
            c, prm = smp._construction, smp.params
            detail = c.detail(prm) if hasattr(c, "detail") else f"s={prm.s}, t={prm.strength}"
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
