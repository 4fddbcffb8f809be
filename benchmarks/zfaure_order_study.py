"""Design study for issue 52: which pixel order (and randomization) ``zfaure`` should use.

Prototype "ordered faure": one global Owen-scrambled Faure sequence per seed in
a prime base ``b`` (pyoa's own ``faure`` sampler, read at pixel 0); pixel
``(x, y)`` of a ``W x H`` image takes the samples ``order(x, y) * N + i``,
``i < N``, where ``order`` is a bijection from the pixels onto
``0 .. W*H - 1`` (so no sample is shared). The orders compared:

``row-major``
    ``y * W + x``: plain global faure, the control (no spatial structure).
``morton``
    Base-``b`` Morton: the digits of ``x`` and ``y`` interleaved, child
    ``dy * b + dx`` at every level (the issue's prototype).
``morton-perm``
    Morton with one random permutation of the ``b x b`` children per level,
    the same in every tile (seeded from the user seed).
``peano``
    The base-``b`` Peano curve (``b`` odd): a serpentine in each ``b x b``
    tile, reflected so that consecutive cells, and consecutive tiles at every
    level, are edge-adjacent [2]_.
``morton-tile-shuffle``
    Morton with an independent random permutation of the children of every
    tile at every level (the issue's "shuffle", reported to weaken the effect).
``morton-fine-shuffle``
    A hybrid: Morton at every level but the finest, where each ``b x b`` tile
    gets its own random permutation of its pixels.
``morton-axis-scramble``
    Morton whose every tile at every level permutes its columns and its rows
    by its own random permutations and is transposed at random (a nested
    scramble of each axis's digits): runs of ``b`` codes stay rows or
    columns. ``zfaure``'s order (docs/spec.md section 5.12), here drawn from
    NumPy's generator rather than pyoa's hashes.

For ``W, H`` not powers of ``b`` the order is computed on the padded
``b^k x b^k`` grid and the codes of the pixels inside the image are replaced by
their ranks, which keeps the order a bijection onto ``0 .. W*H - 1``.

References are plain per-pixel ``faure`` (independent pixel seeds) and
``zsobol`` [1]_ at 16 and 32 spp. Every error image is measured as
:func:`pyoa.analysis.error_spectrum` does (the periodogram normalized so that
white noise is 1; ``low`` is its mean over ``1 <= |k| <= min(W, H) / 8``),
plus

* ``aniso``: the normalized power in the ``kx`` axis band (``|ky| <= 1``)
  over that in the ``ky`` band (``|kx| <= 1``), both at ``1..min(W,H)/8``:
  1 for an isotropic error;
* ``r1x, r1y``: the error image's autocorrelation at lag 1 along x and y;
* ``rbx, rby``: its autocorrelation at lag ``b`` (the tile size);
* ``peak``: the highest bin of the normalized periodogram and its ``(kx, ky)``
  (a periodic artefact shows as a spike, also above ``min(W, H) / 8``).

Run ``python benchmarks/zfaure_order_study.py`` (125 x 125, 25 spp, 8 seeds,
plus a 120 x 100 image) or ``--quick`` (25 x 25, 2 seeds). Writes
``benchmarks/results/zfaure-order.json`` and ``.md`` (``--quick`` too, marked
as quick).

References
----------
.. [1] A. G. M. Ahmed, P. Wonka, "Screen-space blue-noise diffusion of
   Monte Carlo sampling error via hierarchical ordering of pixels",
   ACM Transactions on Graphics 39(6), SIGGRAPH Asia 2020.
.. [2] G. Peano, "Sur une courbe, qui remplit toute une aire plane",
   Mathematische Annalen 36 (1890), 157-160 (odd-base generalization: H. Sagan,
   *Space-Filling Curves*, Springer 1994, ch. 3).
"""

from __future__ import annotations

import argparse
import functools
import hashlib
import json
import math
import time
from pathlib import Path

import numpy as np

import pyoa
from pyoa.analysis.integrands import _lookup
from pyoa.analysis.spectra import error_spectrum, radial_mean

CPU = "Intel Xeon family 6 model 207, 2 cores"
RESULTS = Path(__file__).resolve().parent / "results"
INTEGRANDS = [("ball", 2), ("gaussian", 4), ("pairwise", 4)]
ORDERS = ["row-major", "morton", "morton-perm", "peano", "morton-tile-shuffle", "morton-fine-shuffle",
          "morton-axis-scramble"]


# ---------------------------------------------------------------- orders


def _digits(v: np.ndarray, b: int, k: int) -> list[np.ndarray]:
    """Base-b digits of v, most significant first (k of them)."""
    return [(v // b ** (k - 1 - j)) % b for j in range(k)]


def _rng(seed: int, tag: str) -> np.random.Generator:
    """A generator from a hash of (seed, tag), so each seed gets its own permutations."""
    h = hashlib.sha256(f"{seed}:{tag}".encode()).digest()
    return np.random.default_rng(int.from_bytes(h[:8], "little"))


def _padded_code(name: str, b: int, k: int, seed: int) -> np.ndarray:
    """Position of every cell of the b^k x b^k grid on the named curve, shape (n, n) indexed [y, x]."""
    n = b**k
    y, x = np.mgrid[0:n, 0:n]
    if name == "row-major":
        return y * n + x
    dx, dy = _digits(x, b, k), _digits(y, b, k)
    code = np.zeros((n, n), dtype=np.int64)
    if name == "peano":
        if b % 2 == 0:
            raise ValueError("the Peano curve needs an odd base")
        # t_{2j-1} = k^{sum_{i<j} y_i}(x_j), t_{2j} = k^{sum_{i<=j} x_i}(y_j), k(t) = b-1-t:
        # b - 1 - t keeps the parity of t (b odd), so the digit sums' parities are the cells'.
        sx = np.zeros_like(x)
        sy = np.zeros_like(y)
        for j in range(k):
            sx = sx + dx[j]
            tx = np.where(sy % 2 == 1, b - 1 - dx[j], dx[j])
            ty = np.where(sx % 2 == 1, b - 1 - dy[j], dy[j])
            sy = sy + dy[j]
            code = code * b * b + tx * b + ty
        return code
    prefix = np.zeros((n, n), dtype=np.int64)
    for j in range(k):
        child = dy[j] * b + dx[j]
        if name == "morton-perm":
            child = _rng(seed, f"level{j}").permutation(b * b)[child]
        elif name == "morton-tile-shuffle" or (name == "morton-fine-shuffle" and j == k - 1):
            perms = np.argsort(_rng(seed, f"tiles{j}").random((b ** (2 * j), b * b)), axis=1)
            child = perms[prefix, child]
        elif name == "morton-axis-scramble":
            rng = _rng(seed, f"axes{j}")
            px = np.argsort(rng.random((b ** (2 * j), b)), axis=1)
            py = np.argsort(rng.random((b ** (2 * j), b)), axis=1)
            swap = rng.integers(0, 2, size=b ** (2 * j))[prefix] == 1
            gx, gy = px[prefix, dx[j]], py[prefix, dy[j]]
            child = np.where(swap, gx * b + gy, gy * b + gx)
        elif name not in ("morton", "morton-fine-shuffle"):
            raise ValueError(name)
        prefix = prefix * b * b + dy[j] * b + dx[j]
        code = code * b * b + child
    return code


def pixel_order(name: str, w: int, h: int, b: int, seed: int) -> np.ndarray:
    """Bijection (y, x) -> 0..w*h-1: the padded curve's codes of the image's pixels, ranked."""
    if name == "row-major":
        return np.arange(w * h).reshape(h, w)
    k = max(1, math.ceil(math.log(max(w, h), b) - 1e-12))
    while b**k < max(w, h):
        k += 1
    code = _padded_code(name, b, k, seed)[:h, :w].ravel()
    rank = np.empty(w * h, dtype=np.int64)
    rank[np.argsort(code, kind="stable")] = np.arange(w * h)
    return rank.reshape(h, w)


def _check_curve(name: str, b: int, k: int) -> None:
    """Every code used once; for the Peano curve, consecutive cells edge-adjacent."""
    code = _padded_code(name, b, k, 0)
    n = b**k
    assert np.array_equal(np.sort(code.ravel()), np.arange(n * n)), name
    if name == "peano":
        inv = np.argsort(code.ravel())
        yy, xx = np.divmod(inv, n)
        assert np.all(np.abs(np.diff(xx)) + np.abs(np.diff(yy)) == 1), "peano not continuous"


# ---------------------------------------------------------------- measures


def measure(errs: list[np.ndarray], b: int) -> dict:
    """error_spectrum's normalized periodogram and ``low`` (non-square images: |k| in index units,
    limit min(W, H) / 8, so the two axes' frequency units differ there), plus axis-band anisotropy,
    autocorrelations at lags 1 and b, and the highest bin."""
    h, w = errs[0].shape
    acc = np.zeros((h, w))
    sq = 0.0
    rho = {"r1x": 0.0, "r1y": 0.0, "rbx": 0.0, "rby": 0.0}
    for e in errs:
        sq += float(np.mean(e**2))
        acc += np.abs(np.fft.fft2(e)) ** 2 / (w * h)
        c = e - e.mean()
        v = float(np.mean(c * c))
        for key, lag, axis in (("r1x", 1, 1), ("r1y", 1, 0), ("rbx", b, 1), ("rby", b, 0)):
            a = c[:, :-lag] * c[:, lag:] if axis == 1 else c[:-lag, :] * c[lag:, :]
            rho[key] += float(a.mean()) / v / len(errs)
    power = np.fft.fftshift(acc / len(errs))
    cy, cx = h // 2, w // 2
    power[cy, cx] = 0.0
    power /= power.sum() / (w * h - 1)
    ky, kx = np.mgrid[-cy:h - cy, -cx:w - cx]
    r = np.hypot(kx, ky)
    lim = min(w, h) / 8
    band = (r >= 1) & (r <= lim)
    low = float(power[band].mean())
    aniso = float(power[band & (np.abs(ky) <= 1)].mean() / power[band & (np.abs(kx) <= 1)].mean())
    # A periodic artefact (a pattern repeating every tile) shows as a spike anywhere in the spectrum,
    # also above size / 8 where ``low`` does not look: report the highest bin and where it is.
    top = int(np.argmax(power))
    out = {"low": low, "rmse": math.sqrt(sq / len(errs)), "aniso": aniso, **rho,
           "peak": float(power.flat[top]), "peak_at": [int(kx.flat[top]), int(ky.flat[top])]}
    if w == h:
        out["radial"] = [float(v) for v in radial_mean(power)[1]]
    return out


@functools.lru_cache(maxsize=16)
def _global_faure(total: int, d: int, seed: int, b: int) -> np.ndarray:
    """The first ``total`` points of one global faure sequence (shared by every order of a seed)."""
    return pyoa.sampler("faure", spp=total, dims=d, seed=seed, base=b, backend="numpy").generate([0])[0]


def ordered_faure_errors(order_name: str, f, w: int, h: int, b: int, n: int, seeds: range) -> list[np.ndarray]:
    """Error images of the prototype: pixel (x, y) reads samples order(x, y) * n + i of one global faure."""
    errs = []
    for s in seeds:
        pts = _global_faure(w * h * n, f.d, s, b).astype(np.float64)
        est = f(pts).reshape(w * h, n).mean(axis=1)
        errs.append(est[pixel_order(order_name, w, h, b, s)] - f.exact)
    return errs


def sampler_errors(name: str, f, w: int, h: int, spp: int, b: int, seeds: range) -> list[np.ndarray]:
    """Error images of a catalogue sampler (pixels row-major), as error_spectrum builds them."""
    errs = []
    for s in seeds:
        opts = {"resolution": (w, h)} if name == "zsobol" else {"base": b}
        g = pyoa.sampler(name, spp=spp, dims=f.d, seed=s, backend="numpy", **opts)
        v = f(g.generate(pixels=range(w * h)).astype(np.float64)).mean(axis=1)
        errs.append((v - f.exact).reshape(h, w))
    return errs


# ---------------------------------------------------------------- study


def run(quick: bool) -> dict:
    b, n = 5, 25
    size, nseeds = (25, 2) if quick else (125, 8)
    seeds = range(nseeds)
    for name in ORDERS[1:]:
        _check_curve(name, b, 2)
    shapes = [(size, size)] + ([] if quick else [(120, 100)])
    rows = []
    t0 = time.perf_counter()
    for w, h in shapes:
        for iname, d in INTEGRANDS:
            f = _lookup(iname, d)
            cases = [(f"faure-{o}", lambda o=o: ordered_faure_errors(o, f, w, h, b, n, seeds)) for o in ORDERS]
            cases.append(("faure per-pixel", lambda: sampler_errors("faure", f, w, h, n, b, seeds)))
            if w == h:
                for spp in (16, 32):
                    cases.append((f"zsobol {spp}", lambda spp=spp: sampler_errors("zsobol", f, w, h, spp, b, seeds)))
            for label, make in cases:
                t = time.perf_counter()
                m = measure(make(), b)
                rows.append({"image": f"{w}x{h}", "integrand": f"{iname} {d}D", "sampler": label,
                             "spp": 16 if label == "zsobol 16" else 32 if label == "zsobol 32" else n,
                             "seconds": round(time.perf_counter() - t, 2), **m})
                print(f"{w}x{h} {iname:9s} {label:30s} low {m['low']:.3f} rmse {m['rmse']:.5f} "
                      f"aniso {m['aniso']:.2f} r1 {m['r1x']:+.3f}/{m['r1y']:+.3f} "
                      f"rb {m['rbx']:+.3f}/{m['rby']:+.3f} peak {m['peak']:.1f} at {m['peak_at']}", flush=True)
    # Cross-check: this script's measure against error_spectrum itself (zsobol, ball 2D, square).
    ref = error_spectrum("zsobol", spp=16, size=size, seeds=nseeds, integrand="ball", backend="numpy")
    mine = measure(sampler_errors("zsobol", _lookup("ball", 2), size, size, 16, b, seeds), b)
    check = {"error_spectrum_low": ref.low, "this_low": mine["low"], "error_spectrum_rmse": ref.rmse,
             "this_rmse": mine["rmse"]}
    return {"issue": 52, "cpu": CPU, "base": b, "spp": n, "size": size, "seeds": nseeds, "quick": quick,
            "seconds": round(time.perf_counter() - t0, 1), "measure_check": check, "rows": rows}


# Written from the full run (125 x 125 and 120 x 100, 8 seeds) this file records; a --quick run omits it.
CONCLUSION = """## Which order, and why

**Chosen: the axis-scrambled Morton order** (`morton-axis-scramble`, `zfaure`'s, docs/spec.md section
5.12): base-b Morton in which every b x b tile of every level permutes its columns and its rows by its
own random permutations and is transposed or not at random, all drawn from a hash of the seed and the
digits above the tile (a nested, Owen-style scramble of each axis's digits). Every run of b^2 consecutive
codes is still one b x b tile (a (0,m+2,b)-net in every dimension of a block), and every run of b codes
is still one row or one column of it (a (0,m+1,b)-net): the finer net survives, so neighbouring pixels
along the run still cancel.

Why, from the table:

* It is the only order with both a low `low` and no structure: low 0.27-0.48 (ball 2D 0.32-0.35,
  gaussian 4D 0.46-0.48, pairwise 4D 0.27-0.30), highest bin 2.7-4.2 (per-pixel faure: 2.7-3.1),
  anisotropy 0.80-1.13, autocorrelation at the tile size within +-0.009.
* Plain Morton has the lowest `low` (0.21-0.38), but its error image carries deterministic structure: a
  spectral spike of 127-866 times the white-noise level (the bin survives averaging over 8 seeds, so it
  sits at the same frequency in every image), autocorrelation at the tile size of up to +0.37 (y) and
  -0.20 (x), and anisotropy from 0.63 to 5.3. A denoiser, and the eye, see a pattern, not blue noise.
  The row-major control is no better (spikes 127-671, anisotropy up to 59): a global faure read in
  rows is itself structured, because a row of b^k pixels is a net.
* One permutation per level, the same in every tile (`morton-perm`), leaves a spike at the tile period,
  (0, +-size/5), of 4-39x; `low` 0.41-0.52.
* The Peano curve is strongly anisotropic in 4D (0.06-0.34), has spikes of 15-95x and the worst `low` on
  the ball (0.65-0.77).
* Shuffling each tile's b^2 children (`morton-tile-shuffle`, and `morton-fine-shuffle` at the finest
  level only) removes the structure too, but breaks the rows apart: a run of b codes is then b pixels
  scattered over the tile, no longer neighbours, and `low` rises to 0.40-0.55 (ball 0.53-0.55 against the
  axis scramble's 0.32-0.35).
* Per-pixel RMSE is the same for every order (each permutes the same pixel estimates) and within 4 % of
  per-pixel faure's (ball 0.0568 vs 0.0551, gaussian 0.00927 vs 0.00952, pairwise 0.00586 vs 0.00610).
  Since the orders permute the same estimates, the normalization of the periodogram is the same for all
  of them, so their `low` values compare absolute low-band energy.

This study reads the global sequence in ranked order (a bijection onto 0 .. W*H - 1); `zfaure` uses the
padded grid's codes themselves (z N + i, gaps where the grid passes the image), which keeps every tile of
the grid aligned also when W or H is not a multiple of b.
"""


def markdown(res: dict) -> str:
    lines = [f"# zfaure order study (issue 52, design item 1){' - quick' if res['quick'] else ''}", "",
             f"Base {res['base']}, {res['spp']} spp (zsobol at 16/32), {res['size']} x {res['size']} "
             f"(and 120 x 100 when not quick), {res['seeds']} seeds. CPU: {res['cpu']}; "
             f"study took {res['seconds']} s. Written by `benchmarks/zfaure_order_study.py`.", "",
             "low: mean normalized periodogram at 1 <= |k| <= min(W,H)/8 (white noise 1). aniso: kx-band / "
             "ky-band power at those radii (1 = isotropic). r1x/r1y: error autocorrelation at lag 1; "
             "rbx/rby: at lag b (the tile size). peak: the highest bin of the normalized periodogram, at (kx, ky).", "",
             "| image | integrand | sampler | spp | low | RMSE | aniso | r1x | r1y | rbx | rby | peak |",
             "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in res["rows"]:
        lines.append(f"| {r['image']} | {r['integrand']} | {r['sampler']} | {r['spp']} | {r['low']:.3f} | "
                     f"{r['rmse']:.5f} | {r['aniso']:.2f} | {r['r1x']:+.3f} | {r['r1y']:+.3f} | "
                     f"{r['rbx']:+.3f} | {r['rby']:+.3f} | {r['peak']:.1f} at {tuple(r['peak_at'])} |")
    c = res["measure_check"]
    lines += ["", f"Measure check (zsobol 16, ball 2D): error_spectrum low {c['error_spectrum_low']:.4f}, "
              f"this script {c['this_low']:.4f}; RMSE {c['error_spectrum_rmse']:.5f} vs {c['this_rmse']:.5f}.", ""]
    if not res["quick"]:
        lines += [CONCLUSION]
    return "\n".join(lines)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="25 x 25, 2 seeds, square image only")
    a = p.parse_args()
    res = run(a.quick)
    stem = "zfaure-order"
    (RESULTS / f"{stem}.json").write_text(json.dumps(res, indent=1) + "\n")
    (RESULTS / f"{stem}.md").write_text(markdown(res))
    print(f"wrote {RESULTS / stem}.json/.md in {res['seconds']} s")


if __name__ == "__main__":
    main()
