"""``zfaure`` over NumPy arrays: :mod:`pyoa._arrays.zfaure` bound to :mod:`.ops`."""

from __future__ import annotations

from .._arrays import bind, zfaure as generic
from . import ops

zfaure = bind(ops, generic.zfaure)
