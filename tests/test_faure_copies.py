"""faure's dimensions past one block (docs/spec.md 5.11): each copy reads the
sequence in its own nested order, so it keeps every net of the sequence and
no dimension is a function of another."""

from __future__ import annotations

import numpy as np
import pytest

import pyoa
from tests.helpers import net_failures


@pytest.mark.parametrize("b", [2, 3, 5, 7])
def test_copies_are_nets_and_no_function_of_the_first_block(b):
    m = 3 if b < 7 else 2
    smp = pyoa.sampler("faure", spp=2 * b**m, dims=3 * b, base=b, seed=11, backend="numpy")
    x = smp.generate(pixels=[0, 5, 2**32 - 1])
    for block in (1, 2):  # every aligned block of b^m samples of a copy is a net
        assert not net_failures(x[:, :, block * b:(block + 1) * b], b, m, b)
    # pair (c, c + b) at N = b^2: a function would fill at most b^2 / b ... b cells of b x b
    # (it did, before the copies' index scramble); random pairing fills more in every pixel
    n = b * b
    for c in range(b):
        for other in (c + b, c + 2 * b):
            cells = np.floor(x[:, :n, c] * b).astype(int) * b + np.floor(x[:, :n, other] * b).astype(int)
            filled = [len(set(row)) for row in cells]
            assert b == 2 or min(filled) > b, (c, other, filled)


def test_copies_are_uncorrelated_with_the_first_block():
    """The pixel mean of (x_c - 1/2)(x_(c+b) - 1/2) falls with N; it stayed at
    the variance of a function's product when the copies read sample i."""
    b = 5
    variances = []
    for n in (25, 625):
        smp = pyoa.sampler("faure", spp=n, dims=2 * b, base=b, seed=3, backend="numpy")
        x = smp.generate(pixels=range(200)).astype(np.float64)
        est = ((x[:, :, 0] - 0.5) * (x[:, :, b] - 0.5)).mean(axis=1)
        variances.append(est.var())
    assert variances[1] < variances[0] / 10, variances
