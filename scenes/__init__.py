"""Scene files bundled with pyoa, shipped inside the package as ``pyoa.scenes``.

``setup.cfg`` maps this folder into the package (``package_dir``), so the
``.json`` scenes install with a plain ``pip install .``; the format is
described in :mod:`pyoa.render.scene`, and :func:`pyoa.render.scene.bundled`
lists them. ``cornell`` is Mitsuba 3's ``cornell_box()``; ``dof7d``,
``bounce9d`` and ``deep`` are the low-, mid- and high-dimensional test scenes;
``cornell-glass`` is ``cornell`` with its large box of glass (``dielectric``).
"""
