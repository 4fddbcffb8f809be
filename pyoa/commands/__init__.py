"""The ``pyoa`` command line.

``pyoa points``   generate a point set and save it (.npy or .csv)
``pyoa samplers`` list the samplers, ``pyoa spp NAME`` their valid sample counts
``pyoa backends`` report the usable backends and OpenCL devices
``pyoa plot``     every 2D projection of a point set; ``pyoa spectrum`` its power spectrum,
                  or with ``--error`` the screen-space spectrum of a sampler's integration error
``pyoa render``   render a scene (EXR/PNG); ``pyoa compare`` tabulate samplers'
                  relative MSE against a reference; ``pyoa reference`` render one
``pyoa study``    error against spp over seeds, with confidence intervals
(render, compare, reference and study run on a Dask cluster with
``--workers N`` or ``--scheduler ADDRESS``; in-process by default)

One convention for every command (:data:`~pyoa.commands.options.CONVENTION`,
printed by ``pyoa --help``).

Each module of this package holds a group of commands and adds their parsers
(``add_parsers(sub)``): :mod:`~pyoa.commands.samplers` (points, samplers,
spp, backends, plot, spectrum), :mod:`~pyoa.commands.render` (render,
compare, info, reference) and :mod:`~pyoa.commands.study`;
:mod:`~pyoa.commands.options` holds what they share and
:mod:`~pyoa.commands.main` the parser, the exit statuses and the streams.
A command reads its options and calls a library function with a settings
value (:class:`~pyoa.render.settings.RenderSettings`,
:class:`~pyoa.study.StudySettings`); nothing below this package imports it.
"""

from .main import main

__all__ = ["main"]
