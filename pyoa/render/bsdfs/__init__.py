"""The BSDFs, one module each, and the registry the renderer is built from.

Every direction is a unit ``float64`` vector in the *local* frame of the
shading point, where the shading normal is ``+z``; arrays hold one lane per
shading point, shape ``(N, 3)``. ``wo`` points away from the surface towards
the viewer and the renderer guarantees ``wo[:, 2] > 0``: it turns the shading
normal towards ``wo``, so every surface is two-sided, and tells a BSDF that
needs it (glass) which side of the geometric normal ``wo`` lies on
(``front``). Lanes whose ``wo`` breaks that contract get zero weight, zero
value and zero pdf rather than garbage.

A BSDF is one module of this package (:mod:`.diffuse`, :mod:`.mirror`,
:mod:`.ggx`, :mod:`.dielectric`), holding:

- ``NAME``, the scene's material ``type``, and ``KEYS``, its scene keys with
  their defaults and ranges (:class:`~.base.Key`); ``params(values)`` turns
  the keys' values into the material table's numbers (at most
  :data:`PARAMS`);
- ``DELTA``: every lobe is a Dirac delta (the material gets no light sample,
  and ``evaluate``/``pdf`` are 0);
- its NumPy forms ``sample(p, wo, u, front)`` -> ``(wi, weight, pdf,
  delta)``, ``evaluate(p, wo, wi, front)`` -> ``(f_cos, pdf)`` and ``pdf(p,
  wo, wi, front)``, over lanes with ``wo.z > 0`` (``p``: the lanes'
  material numbers);
- its one-point forms ``sample_point(m0, m1, m2, m3, front, ox, oy, oz, u0,
  u1)`` (called where ``wo.z > 0``) and ``evaluate_point(m0, m1, m2, m3,
  front, ox, oy, oz, ix, iy, iz)`` (0 wherever ``wo`` or ``wi`` is outside its
  support, ``wo.z <= 0`` included), plain Python marked
  :func:`~.base.scalar`, which :mod:`pyoa.render.compiled` compiles;
- ``LANES``: its one-point forms are free of branches, so the compiled
  shading may shade its lanes packed together in vectorized loops (its
  lane form; else one lane at a time).

:data:`BSDFS` lists the modules; a kind's id is its place there, so the
kinds keep their ids (the bundled scenes' images do not change) and a new
BSDF goes at the end. The scene parser's material table
(:mod:`pyoa.render.scene`), :class:`Materials`, the NumPy dispatch below
(:func:`sample`, :func:`evaluate`, :func:`pdf`) and the compiled dispatch
(:mod:`pyoa.render.compiled.bsdfs`, :mod:`pyoa.render.compiled.shading`) are
all built from it: adding a BSDF is its module, its line here and its tests.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import dielectric, diffuse, ggx, mirror
from .base import lanes

__all__ = ["BSDFS", "KINDS", "DELTA", "PARAMS", "Materials", "sample", "evaluate", "pdf"]

#: The BSDF modules in kind order (a kind's id is its index; new ones at the end).
BSDFS = (diffuse, mirror, ggx, dielectric)
#: Material type (a scene's ``type``) -> kind id.
KINDS = {m.NAME: k for k, m in enumerate(BSDFS)}
#: Per kind: every lobe is a Dirac delta (no light sample).
DELTA = np.array([m.DELTA for m in BSDFS], dtype=bool)
DELTA.setflags(write=False)
#: Numbers per material in the table (``Materials.params``), the most any BSDF uses.
PARAMS = 4


@dataclass(frozen=True, eq=False)
class Materials:
    """Parameters of ``M`` materials as arrays (index = material id).

    Attributes
    ----------
    names : tuple of str
        Material names, unique, ``names[i]`` is material id ``i``.
    kind : numpy.ndarray
        ``(M,)`` ``int32``: the BSDF's kind id (:data:`KINDS`).
    params : numpy.ndarray
        ``(M, PARAMS)`` ``float64``: each material's numbers, as its BSDF's
        ``params`` makes them from its scene keys (a colour and a roughness
        for ``ggx``, the ratio of the indices of refraction for
        ``dielectric``, ...), zero-padded.

    The arrays are made read-only. Build instances with :meth:`build`.
    """

    names: tuple[str, ...]
    kind: np.ndarray
    params: np.ndarray

    @classmethod
    def build(cls, specs) -> "Materials":
        """Build the material table from ``(name, type, values)`` tuples.

        Parameters
        ----------
        specs : iterable of tuple
            ``(name, type, values)`` per material, in id order: ``type`` a
            key of :data:`KINDS`, ``values`` a mapping of the BSDF's scene
            keys (``KEYS``) to values; a key left out takes its default.

        Returns
        -------
        Materials

        Raises
        ------
        ValueError
            On an unknown type (the message names the valid ones), a
            duplicate name, a key the BSDF does not have, or a value outside
            its key's range (the message names the key and the range).
        """
        names, kinds, rows = [], [], []
        for spec in specs:
            try:
                name, type_name, values = spec
            except (TypeError, ValueError):
                raise ValueError(f"material spec must be (name, type, values), got {spec!r}") from None
            name = str(name)
            if name in names:
                raise ValueError(f"duplicate material name {name!r}")
            if type_name not in KINDS:
                raise ValueError(f"material {name!r}: unknown type {type_name!r}; valid: {', '.join(sorted(KINDS))}")
            module = BSDFS[KINDS[type_name]]
            values = dict(values)
            keys = {k.name: k for k in module.KEYS}
            for k in values:
                if k not in keys:
                    raise ValueError(f"material {name!r}: {type_name} has no key {k!r}; valid: {', '.join(keys)}")
            try:
                checked = {k: key.check(values.get(k, key.default)) for k, key in keys.items()}
            except ValueError as exc:
                raise ValueError(f"material {name!r}: {type_name} {exc}") from None
            row = tuple(float(x) for x in module.params(checked))
            names.append(name)
            kinds.append(KINDS[type_name])
            rows.append(row + (0.0,) * (PARAMS - len(row)))
        kind = np.asarray(kinds, dtype=np.int32).reshape(-1)
        params = np.asarray(rows, dtype=np.float64).reshape(-1, PARAMS)
        for arr in (kind, params):
            arr.setflags(write=False)
        return cls(tuple(names), kind, params)


# --------------------------------------------------------------------------- NumPy dispatch


def _inputs(mats: Materials, mat, wo, front):
    """``(kind, p, wo, front, valid)`` per lane: the kind and numbers of each
    lane's material, ``wo`` as ``(N, 3)`` float64, ``front`` (all True when
    not given) and where ``wo.z > 0``."""
    mat = np.asarray(mat).reshape(-1)
    wo = np.asarray(wo, dtype=np.float64).reshape(-1, 3)
    front = (np.ones(len(mat), dtype=bool) if front is None
             else np.broadcast_to(np.asarray(front, dtype=bool).reshape(-1), (len(mat),)))
    return mats.kind[mat], mats.params[mat], wo, front, wo[:, 2] > 0.0


def sample(mats: Materials, mat: np.ndarray, wo: np.ndarray, u: np.ndarray, front: np.ndarray | None = None):
    """Sample an incident direction ``wi`` per shading point.

    Parameters
    ----------
    mats : Materials
        The material table.
    mat : numpy.ndarray
        ``(N,)`` integer material ids.
    wo : numpy.ndarray
        ``(N, 3)`` unit outgoing directions in the local frame, ``wo[:, 2] > 0``.
    u : numpy.ndarray
        ``(N, 2)`` uniform samples in ``[0, 1)``.
    front : numpy.ndarray, optional
        ``(N,)`` bool: ``wo`` lies on the side of the geometric normal
        (default: all True). Only BSDFs with two sides (glass) read it.

    Returns
    -------
    wi : numpy.ndarray
        ``(N, 3)`` unit sampled directions.
    weight : numpy.ndarray
        ``(N, 3)`` throughput weight :math:`f(\\omega_o,\\omega_i) |\\cos\\theta_i|
        / p(\\omega_i)` (for a delta lobe: its weight).
    pdf : numpy.ndarray
        ``(N,)`` solid-angle density of ``wi``, equal to :func:`pdf` at
        ``wi``; 0 for delta lobes (read ``delta``).
    delta : numpy.ndarray
        ``(N,)`` bool, True for delta lobes.

    Each kind's lanes are sampled by its module's ``sample``; lanes with
    ``wo.z <= 0`` get ``wi = +z``, weight 0 and pdf 0.
    """
    kind, p, wo, front, valid = _inputs(mats, mat, wo, front)
    u = np.asarray(u, dtype=np.float64).reshape(-1, 2)
    n = wo.shape[0]
    wi = np.zeros((n, 3))
    wi[:, 2] = 1.0
    weight = np.zeros((n, 3))
    pd = np.zeros(n)
    delta = DELTA[kind]
    for k, module in enumerate(BSDFS):
        m = lanes((kind == k) & valid)
        if m is not None:
            wi[m], weight[m], pd[m], delta[m] = module.sample(p[m], wo[m], u[m], front[m])
    return wi, weight, pd, delta


def evaluate(mats: Materials, mat: np.ndarray, wo: np.ndarray, wi: np.ndarray, front: np.ndarray | None = None):
    """Evaluate the BSDF times the cosine and the sampling density.

    Parameters
    ----------
    mats : Materials
        The material table.
    mat : numpy.ndarray
        ``(N,)`` integer material ids.
    wo, wi : numpy.ndarray
        ``(N, 3)`` unit directions in the local frame, ``wo[:, 2] > 0``.
    front : numpy.ndarray, optional
        As for :func:`sample`.

    Returns
    -------
    f_cos : numpy.ndarray
        ``(N, 3)`` :math:`f(\\omega_o,\\omega_i) |\\cos\\theta_i|`.
    pdf : numpy.ndarray
        ``(N,)`` the solid-angle density with which :func:`sample` produces
        ``wi``.

    Both are 0 for delta lobes, for ``wi`` outside a BSDF's support (below
    the surface for the reflective ones) and where ``wo.z <= 0``.
    """
    kind, p, wo, front, valid = _inputs(mats, mat, wo, front)
    wi = np.asarray(wi, dtype=np.float64).reshape(-1, 3)
    n = wo.shape[0]
    f_cos = np.zeros((n, 3))
    pd = np.zeros(n)
    for k, module in enumerate(BSDFS):
        m = lanes((kind == k) & valid)
        if m is not None:
            f_cos[m], pd[m] = module.evaluate(p[m], wo[m], wi[m], front[m])
    return f_cos, pd


def pdf(mats: Materials, mat: np.ndarray, wo: np.ndarray, wi: np.ndarray, front: np.ndarray | None = None):
    """``(N,)`` the solid-angle density with which :func:`sample` produces
    ``wi`` (:func:`evaluate`'s second output, without the BSDF's value)."""
    kind, p, wo, front, valid = _inputs(mats, mat, wo, front)
    wi = np.asarray(wi, dtype=np.float64).reshape(-1, 3)
    pd = np.zeros(wo.shape[0])
    for k, module in enumerate(BSDFS):
        m = lanes((kind == k) & valid)
        if m is not None:
            pd[m] = module.pdf(p[m], wo[m], wi[m], front[m])
    return pd
