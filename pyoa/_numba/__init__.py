"""numba-compiled mirrors of :mod:`pyoa.reference`, one value at a time, for
compiled code that needs them inside its own loops (the renderer's compiled
shading, the pmj02 table builder). Importing :mod:`pyoa` does not import
numba; only the modules that compile import this package."""
