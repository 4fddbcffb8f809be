"""The C sources of pyoa, shipped inside the package as ``pyoa.kernels``.

``setup.cfg`` maps this folder into the package (``package_dir``), so the
files are installed with a plain ``pip install .``:

- ``include/pyoa/*.h``: the spec as portable C (hashes, float rules, hash
  keys, the language configuration) that OpenCL C, C99, C++14 and CUDA
  compile unchanged; ``pyoa.get_include()`` names ``include/`` for C, C++
  and CUDA builds (:mod:`pyoa.c_headers`);
- ``*.cl``: the OpenCL kernels built on those headers.

:mod:`pyoa._opencl.program` reads them with :mod:`importlib.resources` and
concatenates :data:`HEADERS`, then the ``.cl`` files in :data:`SOURCES`
order (each relies only on those before it); a header's ``#include`` lines
are dropped there, since every header it names comes before it.
"""

#: The portable headers under include/pyoa/, in dependency order.
HEADERS = ("config.h", "keys.h", "hashes.h", "floats.h")
#: The kernel sources in dependency order.
SOURCES = ("gf.cl", "oa.cl", "baselines.cl", "zsobol.cl", "pmj02.cl", "faure.cl", "generate.cl")
#: The vector path's program (pyoa._opencl.vector): built per request shape,
#: with that shape's constants as defines.
VECTOR_SOURCES = ("baselines.cl", "vector.cl")
