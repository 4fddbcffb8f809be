"""pyoa: orthogonal-array sampling for Monte Carlo rendering.

Stateless, hash-based orthogonal-array samplers after Jarosz et al.,
"Orthogonal Array Sampling for Monte Carlo Rendering" (EGSR 2019), and the
paper's comparison samplers (random, padded jittered / CMJ / (0,2), Halton,
Sobol), computed in bulk by OpenCL kernels (PoCL by default), a NumPy
fallback, or one value at a time by the pure-Python reference, all with the
same float32 bits.

>>> import pyoa
>>> smp = pyoa.sampler("bose", spp=121, dims=8, seed=7)
>>> x = smp.generate(pixels=range(16))        # float32, shape (16, 121, 8)
"""

from . import reference
from .backends import PyoaFallbackWarning, backends
from .c_headers import get_include
from .catalogue import valid_spp
from .catalogue.entries import OFFSETS, SppChoice
from .samplers import Sampler, sampler, samplers

__version__ = "0.1.0"

__all__ = [
    "sampler", "samplers", "Sampler", "valid_spp", "SppChoice", "backends", "reference",
    "OFFSETS", "PyoaFallbackWarning", "get_include", "__version__",
]


def __getattr__(name):
    # Submodules with heavier imports (scipy, matplotlib, embreex) load on
    # first use: `pyoa.qmc.OrthogonalArray` works without importing them up front.
    if name in ("qmc", "analysis", "plots", "render"):
        import importlib

        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
