"""The NumPy fallback backend: vectorized mirrors of :mod:`pyoa.reference`."""
