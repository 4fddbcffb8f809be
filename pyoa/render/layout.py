"""Which sampler dimension feeds which integrand dimension: the one place
that defines the renderer's dimension layout.

A camera path consumes, in this order (the *integrand* dimensions):

====================  =====================================================
``pixel.x, pixel.y``  position inside the pixel (the pixel filter)
``lens.u, lens.v``    point on the thin lens (only if the camera has an aperture)
``time``              time in the shutter interval (only if the camera moves)
``light<k>.u, .v``    light sample at path vertex k = 1, 2, ... (choice of
                      emitter triangle and point on it)
``bsdf<k>.u, .v``     BSDF sample at vertex k (omitted at the last vertex
                      when the scene turns multiple importance sampling off)
====================  =====================================================

Vertex k exists for ``k = 1 .. max_depth - 1`` (``max_depth`` counts path
segments, as Mitsuba's does). By default integrand dimension ``d`` is
sampler dimension ``d``; ``first=`` moves named integrand dimensions to the
front, so that they land in the first block of an orthogonal array (the
paper's point that the dimensions that matter should be stratified jointly).
Russian roulette does not consume a sampler dimension (it uses a hash of
the pixel, sample and depth).
"""

from __future__ import annotations

from ..catalogue.entries import MAX_DIMS

#: Longest path (segments) whose layout fits in a sampler's MAX_DIMS
#: dimensions: pixel 2 + lens 2 + time 1 + 4 per vertex.
MAX_DEPTH = (MAX_DIMS - 5) // 4 + 1


class Layout:
    """The dimension layout of one render.

    Parameters
    ----------
    max_depth : int
        Longest path in segments, in [1, MAX_DEPTH].
    mis : bool
        Whether the last vertex also takes a BSDF sample (multiple
        importance sampling of emitter hits).
    lens, time : bool
        Whether the camera has an aperture / moves.
    first : sequence of str, optional
        Integrand dimensions (names as above, or a prefix such as
        ``"light1"`` for both of its coordinates) to map to the first
        sampler dimensions, in this order.
    """

    def __init__(self, *, max_depth: int, mis: bool, lens: bool, time: bool, first=None):
        if not 1 <= max_depth <= MAX_DEPTH:  # checked before a loop over the vertices
            raise ValueError(f"max_depth must be in [1, {MAX_DEPTH}], got {max_depth}")
        # a str is itself a sequence (of letters): first="light1" would be read as 'l', 'i', ...
        if isinstance(first, str) or not isinstance(first, (list, tuple, type(None))) \
                or not all(isinstance(n, str) for n in first or ()):
            raise TypeError(f"first must be a sequence of integrand dimension names, such as ['light1'] or "
                            f"('pixel.x', 'pixel.y'), got {type(first).__name__} {first!r}"
                            + (f"; for one name, give [{first!r}]" if isinstance(first, str) else ""))
        names = ["pixel.x", "pixel.y"]
        if lens:
            names += ["lens.u", "lens.v"]
        if time:
            names += ["time"]
        for k in range(1, max_depth):
            names += [f"light{k}.u", f"light{k}.v"]
            if mis or k < max_depth - 1:
                names += [f"bsdf{k}.u", f"bsdf{k}.v"]
        self.max_depth, self.mis, self.lens, self.time = max_depth, mis, lens, time
        self.integrand = tuple(names)
        order = []
        for want in first or ():
            match = [n for n in names if n == want or n.split(".")[0] == want]
            if not match:
                raise ValueError(f"unknown integrand dimension {want!r}; valid: {', '.join(names)} "
                                 "(or a prefix such as 'light1')")
            order += [n for n in match if n not in order]
        order += [n for n in names if n not in order]
        #: integrand dimension names in sampler order
        self.names = tuple(order)
        self._index = {n: i for i, n in enumerate(order)}

    @property
    def dims(self) -> int:
        """Number of sampler dimensions a camera path uses."""
        return len(self.names)

    def __contains__(self, name: str) -> bool:
        return name in self._index

    def index(self, name: str) -> int:
        """The sampler dimension of integrand dimension ``name``."""
        return self._index[name]

    def pair(self, prefix: str) -> tuple[int, int]:
        """Sampler dimensions of ``prefix.u/.v`` (or ``.x/.y``)."""
        if f"{prefix}.u" in self._index:
            return self._index[f"{prefix}.u"], self._index[f"{prefix}.v"]
        return self._index[f"{prefix}.x"], self._index[f"{prefix}.y"]

    def describe(self) -> str:
        return ", ".join(f"{i}:{n}" for i, n in enumerate(self.names))
