"""pyoa's host-side path tracer: Embree (through embreex) for rays, pyoa's
samplers for every random number, shading compiled with numba (and its NumPy
reference), OpenImageIO for images.

Modules: :mod:`.render` (``render`` and ``plan``: batches, threads, memory),
:mod:`.settings` (a render's settings as one value, ``RenderSettings``),
:mod:`.scene` (scene files: validation, shapes, camera),
:mod:`.bsdfs` (materials, one module per BSDF: scene keys, sampling, evaluation, pdfs),
:mod:`.geometry` (frames and small vector helpers), :mod:`.integrator`
(the wavefront path tracer), :mod:`.image` (EXR/PNG output).
"""
