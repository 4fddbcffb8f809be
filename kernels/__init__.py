"""The C sources of pyoa, shipped inside the package as ``pyoa.kernels``.

``setup.cfg`` maps this folder into the package (``package_dir``), so the
files are installed with a plain ``pip install .``:

- ``include/pyoa/*.h``: the spec as portable C that OpenCL C, C99, C++14
  and CUDA compile unchanged: every sampler's value (hashes, float rules,
  Galois fields, the orthogonal arrays' cells, block rule and tail, the
  comparison and progressive samplers), the hash keys and catalogue codes,
  the host-side table builders and the renderer API (``sampler.h``,
  ``sampler.hpp``); ``pyoa.get_include()`` names ``include/`` for C, C++
  and CUDA builds (:mod:`pyoa.c_headers`);
- ``*.cl``: the OpenCL kernels (launch shapes and memory layouts only),
  which call those headers' value functions.

:mod:`pyoa._opencl.program` reads them with :mod:`importlib.resources` and
concatenates :data:`HEADERS`, then the ``.cl`` files in :data:`SOURCES`
order (each relies only on those before it); a header's ``#include`` lines
are dropped there, since every header it names comes before it.
"""

#: The portable headers under include/pyoa/ that the OpenCL programs use, in
#: dependency order (the host-only ones, tables and the renderer API, are
#: not part of them).
HEADERS = ("config.h", "keys.h", "hashes.h", "floats.h", "gf.h", "oa.h", "baselines.h", "zsobol.h", "pmj02.h",
           "faure.h", "zfaure.h", "values.h")
#: The kernel sources of the bulk program.
SOURCES = ("generate.cl",)
#: The vector path's program (pyoa._opencl.vector): built per request shape,
#: with that shape's constants as defines.
VECTOR_SOURCES = ("vector.cl",)
