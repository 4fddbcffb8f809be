"""The ``pyoa`` command line.

``pyoa points``   generate a point set and save it (.npy or .csv)
``pyoa samplers`` list the samplers, ``pyoa spp NAME`` their valid sample counts
``pyoa backends`` report the usable backends and OpenCL devices
``pyoa plot``     every 2D projection of a point set; ``pyoa spectrum`` its power spectrum
``pyoa render``   render a scene (EXR/PNG); ``pyoa compare`` tabulate samplers'
                  relative MSE against a reference; ``pyoa reference`` render one
``pyoa study``    error against spp over seeds, with confidence intervals
(render, compare, reference and study run on a Dask cluster with
``--workers N`` or ``--scheduler ADDRESS``; in-process by default)

One convention for every command (:data:`CONVENTION`, printed by ``pyoa --help``).
"""

from .main import main

__all__ = ["main"]
