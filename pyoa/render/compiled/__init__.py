"""The path tracer's shading compiled with numba, Embree called from it.

It mirrors the NumPy reference (:mod:`pyoa.render.integrator`,
:mod:`pyoa.render.bsdf`, :mod:`pyoa.render.geometry`) function by function,
one lane at a time, and traces through :mod:`pyoa.render.embree`. Chosen with
``shading="numba"`` (the default), ``pyoa render --shading`` or
``PYOA_SHADING``.
"""
