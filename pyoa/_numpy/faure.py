"""The Owen-scrambled Faure sequence over NumPy arrays: :mod:`pyoa._arrays.faure` bound to :mod:`.ops`."""

from __future__ import annotations

from .._arrays import bind, faure as generic
from . import ops

faure = bind(ops, generic.faure)
