"""OpenCL C sources of pyoa, shipped inside the package as ``pyoa.kernels``.

``setup.cfg`` maps this folder into the package (``package_dir``), so the
``.cl`` files are installed with a plain ``pip install .``. They are read with
:mod:`importlib.resources` and concatenated in :data:`SOURCES` order by
:mod:`pyoa._opencl.program`: each file relies only on those before it.
"""

#: The kernel sources in dependency order.
SOURCES = ("hashes.cl", "floats.cl", "gf.cl", "oa.cl", "baselines.cl", "zsobol.cl", "pmj02.cl", "faure.cl", "generate.cl")
#: The vector path's program (pyoa._opencl.vector): built per request shape,
#: with that shape's constants as defines.
VECTOR_SOURCES = ("hashes.cl", "floats.cl", "baselines.cl", "vector.cl")
