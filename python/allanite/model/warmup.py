"""A warm-up's parameters, estimated against the record's own noise: generalised least squares on block means.

The block means of a gyro's rate are not independent: flicker (B) and random walk of rate (K) tie them over the
whole record. An ordinary least-squares fit of a·e^{−t/T} treats them as independent and trades T against the
wander — its intervals then exclude the truth (issue 29: T = 2837 s, [2567, 3136], for a 1500 s warm-up in
ADIS16405 noise). Here the block means' covariance under the fitted noise terms is written out
(:func:`block_covariance`) and the warm-up c + a·e^{−t/T} is fitted by GLS, T profiled on a fine grid, a rate
ramp R·t (when the noise terms hold one) a free column: it is a deterministic slope of unknown size. The
intervals are where the GLS χ² rises over its minimum by at most a threshold from a parametric bootstrap of the
profile's likelihood ratio (1 for a model linear in T; more where T is poorly determined), for T directly and for
a as the profile over T of its conditional interval. The noise terms come from a five-term fit of the record
with the warm-up removed, and the fit is repeated once with them (:func:`warmup_fit`); whether a rate ramp is a
free column then is decided by the block means' likelihood (:func:`ramp_choice`), not by the fitted R alone —
on one record a five-term fit tells a ramp from a random walk of rate poorly, and a real ramp left out is taken
by the warm-up.

What is achievable: :func:`warmup_crlb`, the Cramér–Rao bound of (a, T) under given noise terms. A warm-up is
read mostly against the flicker and random walk at its own time scale, so the bound falls with the amplitude
(∝ 1/a) and hardly with the record's length: for 0.08 °/s·e^{−t/1500 s} in ADIS16405 run 4 x noise it is
sd(T)/T ≥ 46–66 % on 10⁶ samples at 100 Hz; the GLS against the true noise terms has a median |T error| of
22–37 % there, this fit against the record's own 26–52 % (13 % at twice the amplitude on the first noise;
benches/results/warmup_coverage.md).

Covariance of the means b_i of blocks [s_i, e_i) of w_i = e_i − s_i seconds (two-sided PSDs of IEEE Std 952):

- white rate N (S = N²): N²/w_i on the diagonal;
- random walk of rate K from the record's start (Brownian, K²·min(s, t)): K²·(s_i + w_i/3) on the diagonal,
  K²·(s_i + e_i)/2 off it (i < j);
- flicker B (S = B²/(2πf)): a sum of Gauss–Markov processes with correlation times spaced by e^{1/2} from a
  twentieth of a block to 10 record lengths, each of variance B²·ln(e^{1/2})/π (their Lorentzians add up to
  B²/(2πf) across the band); a GM of time constant T adds σ²·T²(1 − e^{−w_i/T})(1 − e^{−w_j/T})·
  e^{−(s_j − e_i)/T}/(w_i w_j) off the diagonal and σ²·2T(w − T(1 − e^{−w/T}))/w² on it;
- a ramp R·t: in :func:`block_covariance` a random slope of variance R², R²·(t_i − t̄)(t_j − t̄); the fits
  take it as a free column instead (a random slope of the size the curve gives shrinks the ramp towards zero
  and the warm-up takes the rest).

Constant parts of the covariance (the slowest processes' common level) do not move a GLS fit with an intercept.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import solve_triangular

from ..analysis import avar
from .fitting import fit

__all__ = [
    "block_covariance",
    "gls_warmup",
    "warmup_fit",
    "warmup_component",
    "warmup_heldout",
    "warmup_crlb",
    "noise_terms",
    "ramp_choice",
    "BLOCKS",
    "T_GRID_POINTS",
    "HELDOUT_MIN_GROUPS",
    "HELDOUT_Z",
]

#: Block means the warm-up is fitted to (as the drift test's).
BLOCKS = 500
#: Points of the log-T grid the GLS χ² is profiled on (from L/200 to L/2).
T_GRID_POINTS = 241
#: Records of the parametric bootstrap that sets the profile interval's threshold.
BOOTSTRAP = 400
#: The intervals' coverage (one standard deviation of a normal).
LEVEL_68 = 0.6827
#: Log-likelihood gain a free rate ramp must bring to be fitted (:func:`ramp_choice`; Akaike: one parameter).
RAMP_GAIN = 1.0
#: Random walks of rate the ramp's choice weighs each design at, × the block means' spread over √(length).
_K_GRID = np.geomspace(1e-3, 10.0, 25)
#: Ratio of successive Gauss–Markov time constants in the flicker sum, as a log.
_FLICKER_STEP = 0.5


def block_covariance(edges: np.ndarray, N: float = 0.0, B: float = 0.0, K: float = 0.0, R: float = 0.0) -> np.ndarray:
    """Covariance of the rate's means over blocks [edges[i], edges[i+1]) (s) for the noise terms N, B, K, R
    (the rate unit's base form: unit/√s, unit, unit/s^1.5, unit/s²)."""
    e = np.asarray(edges, dtype=np.float64)
    return _cov_of_blocks(np.column_stack([e[:-1], e[1:]]), {"N": N, "B": B, "K": K, "R": R})


def _flicker(s0, s1, w, length) -> np.ndarray:
    """Block-mean covariance of unit flicker (two-sided PSD 1/(2πf)) as a sum of Gauss–Markov processes."""
    var = _FLICKER_STEP / math.pi
    out = np.zeros((w.size, w.size))
    gap = s0[None, :] - s1[:, None]  # s_j − e_i: ≥ 0 above the diagonal
    gap = np.where(gap >= 0, gap, gap.T)
    for lt in np.arange(math.log(0.05 * w.min()), math.log(10.0 * length), _FLICKER_STEP):
        t = math.exp(lt)
        f = t * -np.expm1(-w / t) / w
        blk = np.outer(f, f) * np.exp(-gap / t)
        blk[np.diag_indices(w.size)] = 2.0 * t * (w - t * -np.expm1(-w / t)) / (w * w)
        out += var * blk
    return out


def gls_warmup(b: np.ndarray, tb: np.ndarray, cov: np.ndarray, length: float, ramp: bool = False) -> dict:
    """GLS fit of c + a·e^{−t/T} (+ r·t with ``ramp``) to block means ``b`` at times ``tb`` with covariance
    ``cov``, T profiled on a log grid over [L/200, L/2]; 68.3 % profile intervals for T and a, where the GLS
    χ² rises over its minimum by at most the threshold a parametric bootstrap of the profile's likelihood
    ratio at the fitted T gives (:func:`_lr_threshold`; 1 for a linear model, more where T is poorly
    determined and the profile is far from parabolic)."""
    chi2, cols, norm2, q0, u, grid = _profile(_cholesky(cov), b, tb, length, ramp)
    amp, se = u / norm2, 1.0 / np.sqrt(norm2)
    j = int(np.argmin(chi2))
    thr = _lr_threshold(cols, norm2, q0, amp[j] * cols[:, j], j)
    room = chi2[j] + thr - chi2
    inside = room >= 0
    half = se[inside] * np.sqrt(room[inside])
    return {
        "T": math.exp(grid[j]),
        "amplitude": float(amp[j]),
        "T_interval": (math.exp(grid[inside].min()), math.exp(grid[inside].max())),
        "amplitude_interval": (float(np.min(amp[inside] - half)), float(np.max(amp[inside] + half))),
        "chi2": float(chi2[j]),
        "threshold": thr,
        "at_edge": j in (0, grid.size - 1),
    }


def _profile(chol: np.ndarray, b: np.ndarray, tb: np.ndarray, length: float, ramp: bool, white=None):
    """The GLS χ² of c + a·e^{−t/T} (+ r·t) over the log-T grid, whitened by the Cholesky factor ``chol``:
    (χ², the warm-up's whitened columns with the constant (and ramp) projected out, their squared norms, the
    projector's basis, the columns' products with the residual, the grid of ln T). ``white``: the whitened
    (block means, warm-up columns) from :func:`_whitened`, where several designs share one factor."""
    grid = np.linspace(math.log(length / 200.0), math.log(length / 2.0), T_GRID_POINTS)
    wb, cols = _whitened(chol, b, tb, grid) if white is None else white
    base = [np.ones_like(tb)] + ([tb - tb.mean()] if ramp else [])
    q0 = np.linalg.qr(solve_triangular(chol, np.column_stack(base), lower=True))[0]
    cols = cols - q0 @ (q0.T @ cols)  # the warm-up's columns with the constant (and ramp) projected out
    norm2 = np.maximum(np.sum(cols * cols, axis=0), 1e-300)
    r0 = wb - q0 @ (q0.T @ wb)
    u = cols.T @ r0
    return float(r0 @ r0) - u * u / norm2, cols, norm2, q0, u, grid


def _whitened(chol: np.ndarray, b: np.ndarray, tb: np.ndarray, grid: np.ndarray):
    """The block means and the warm-up's columns e^{−t/T} (T = e^grid) whitened by the Cholesky factor."""
    cols = np.exp(-tb[:, None] / np.exp(grid)[None, :])
    return solve_triangular(chol, b, lower=True), solve_triangular(chol, cols, lower=True)


def _lr_threshold(cols: np.ndarray, norm2: np.ndarray, q0: np.ndarray, signal: np.ndarray, j: int) -> float:
    """The 68.3 % quantile of χ²(T̂) − min_T χ²(T) over :data:`BOOTSTRAP` records drawn from the fit (the
    whitened warm-up at the fitted T plus unit white noise, constant and ramp projected out as in the fit):
    the profile interval's threshold with the model's own nonlinearity. All records at once (a matrix
    product per record batch); a fixed seed, so the same record gets the same interval."""
    z = np.random.default_rng(0).standard_normal((signal.size, BOOTSTRAP))
    r = signal[:, None] + z - q0 @ (q0.T @ z)
    u = cols.T @ r
    fit_gain = u * u / norm2[:, None]
    lr = fit_gain.max(axis=0) - fit_gain[j]
    return float(np.quantile(lr, LEVEL_68))


def _cholesky(cov: np.ndarray) -> np.ndarray:
    """Cholesky factor of ``cov``; where rounding of its slow (nearly constant) parts leaves it indefinite, of
    the nearest positive definite matrix (eigenvalues clipped at 1e-10 of the largest)."""
    try:
        return np.linalg.cholesky(cov)
    except np.linalg.LinAlgError:
        w, v = np.linalg.eigh(0.5 * (cov + cov.T))
        w = np.maximum(w, 1e-10 * float(w.max()))
        return np.linalg.cholesky((v * w) @ v.T)


def _blocks(y: np.ndarray, fs: float, n_blocks: int):
    nb = max(3, min(n_blocks, y.size // 2))
    per = y.size // nb
    b = y[: nb * per].reshape(nb, per).mean(axis=1)
    edges = np.arange(nb + 1) * per / fs
    return b, edges


def warmup_fit(
    y: np.ndarray, fs: float, noise, refit_noise=None, n_blocks: int = BLOCKS, ramp: bool | None = None
) -> dict:
    """(a, T) of a warm-up in ``y`` with intervals, by GLS against ``noise`` ({"N", "B", "K", "R"}, base form).

    ``refit_noise(z)``, if given, returns the noise terms of the record ``z`` (the warm-up removed): the fit is
    then repeated once with them, so that the warm-up no longer inflates the noise it is weighed against, and
    whether a free rate ramp is fitted is decided by the block means' likelihood (:func:`ramp_choice`) instead
    of by the fitted R alone. ``ramp`` forces the free ramp column on or off; by default it follows
    ``noise["R"] > 0`` for noise terms given as known. The result also holds the noise terms used
    (``"noise"``) and whether the ramp was fitted (``"ramp"``)."""
    b, edges = _blocks(y, fs, n_blocks)
    tb = 0.5 * (edges[:-1] + edges[1:])
    length = y.size / fs
    use_ramp = _has_ramp(noise) if ramp is None else ramp
    out = gls_warmup(b, tb, _cov_of_blocks(_pairs(edges), _slow_free(noise)), length, ramp=use_ramp)
    if refit_noise is not None:
        t = np.arange(y.size) / fs
        noise = refit_noise(y - out["amplitude"] * np.exp(-t / out["T"]))
        if ramp is None:
            use_ramp, gain = ramp_choice(b, edges, noise)
        out = gls_warmup(b, tb, _cov_of_blocks(_pairs(edges), _slow_free(noise)), length, ramp=use_ramp)
        if ramp is None:
            out["ramp_gain"] = gain
    out["noise"] = dict(noise)
    out["ramp"] = bool(use_ramp)
    return out


def ramp_choice(b: np.ndarray, edges: np.ndarray, noise: dict) -> tuple[bool, float]:
    """Whether the block means ``b`` (blocks between ``edges``, s) hold a rate ramp r·t beside the warm-up:
    (the choice, the log-likelihood gain of the ramp's column).

    A deterministic ramp and a random walk of rate both rise as the longest τ of the Allan curve, and on one
    record a five-term fit takes one for the other (it sets R = 0 on a fifth of records of the ADIS run 4 x
    final model, whose slow part is a ramp; R > 0 on two in five of its five-term fit's, a random walk).
    Without the column a real ramp is taken by the warm-up (T's median error −56 % there); with it where
    there is none, T loses its information to the column. So both designs are weighed by the block means'
    Gaussian likelihood, each at its best random walk K (a grid, :data:`_K_GRID` × the block means' spread
    over √L; K = 0 included) and T (profiled), N and B from ``noise``; the ramp is kept when it raises the
    log-likelihood by more than :data:`RAMP_GAIN` (Akaike: one more parameter)."""
    pairs = _pairs(edges)
    length = float(edges[-1] - edges[0])
    tb = 0.5 * (pairs[:, 0] + pairs[:, 1])
    base = _cov_of_blocks(pairs, {"N": noise.get("N", 0.0), "B": noise.get("B", 0.0)})
    unit_rw = _cov_of_blocks(pairs, {"K": 1.0})
    scale = float(np.std(b)) / math.sqrt(length)
    grid = np.linspace(math.log(length / 200.0), math.log(length / 2.0), T_GRID_POINTS)
    best = {False: -math.inf, True: -math.inf}
    for k in np.concatenate([[0.0], scale * _K_GRID]):
        chol = _cholesky(base + k * k * unit_rw)
        logdet = 2.0 * float(np.sum(np.log(np.diag(chol))))
        white = _whitened(chol, b, tb, grid)
        for r in best:
            chi2 = _profile(chol, b, tb, length, r, white)[0]
            best[r] = max(best[r], -0.5 * (logdet + float(chi2.min())))
    gain = best[True] - best[False]
    return gain > RAMP_GAIN, gain


def noise_terms(z: np.ndarray, fs: float) -> dict:
    """N, B, K, R (base form) of a five-term fit to the octave Allan curve of ``z``, the shortest τ cut where a
    sensor's bandwidth bends them (``tau_range="auto"``): what the block means are weighed against."""
    f = fit(avar(z, fs, taus="octave"), tau_range="auto")
    return {k: float(f.coefficients[k].value) for k in ("N", "B", "K", "R")}


def warmup_component(
    z: np.ndarray,
    t: np.ndarray,
    noise: dict,
    length: float,
    pieces: int = 1,
    n_blocks: int = BLOCKS // 2,
    ramp: bool | None = None,
):
    """The warm-up fitted as :func:`warmup_fit` does on samples ``z`` taken at times ``t`` (s) — a part of
    alternate blocks: its ``pieces`` runs of consecutive samples are each cut into block means, so no block
    straddles a seam, and the blocks' covariance follows their real times. Returns the component as a function
    of time (s), for the held-out error. ``ramp``: fit a free rate ramp (by default where ``noise["R"] > 0``;
    pass :func:`warmup_fit`'s ``"ramp"``)."""
    fs = (t.size - 1) / max(t[-1] - t[0], 1e-300) if t.size > 1 else 1.0
    run = z.size // pieces
    per = max(1, run // max(1, n_blocks // pieces))
    use = (run // per) * per
    zb = z[: pieces * run].reshape(pieces, run)[:, :use].reshape(-1, per).mean(axis=1)
    starts = t[: pieces * run].reshape(pieces, run)[:, :use].reshape(-1, per)[:, 0]
    edges = np.column_stack([starts, starts + per / fs])
    cov = _cov_of_blocks(edges, _slow_free(noise))
    d = gls_warmup(zb, edges.mean(axis=1), cov, length, ramp=_has_ramp(noise) if ramp is None else ramp)
    a, t_c = d["amplitude"], d["T"]
    if not math.exp(-float(edges[0, 0]) / t_c) >= SEEN_MIN:
        # the part starts after the warm-up it fits has decayed: its amplitude is an extrapolation the part cannot
        # determine (a part of late blocks once read 10¹⁴⁷ on a 25 h swing) — it predicts no warm-up
        return lambda tt: np.zeros(np.shape(tt))
    return lambda tt: a * np.exp(-np.asarray(tt) / t_c)


#: The least share of its amplitude a warm-up fitted on a part of the record must show within that part
#: (:func:`warmup_component`): below it the part only extrapolates.
SEEN_MIN = 1e-3


#: The held-out test's interleave: at least this many groups of block means (half held in, half held out).
HELDOUT_MIN_GROUPS = 8
#: The held-out test's z (:func:`warmup_heldout`) a warm-up must reach: what the held-out part gains from it, in
#: standard deviations of that gain for a component fitted to the noise alone. On 20 records of random walk and
#: flicker (10 Hz–1 kHz × 2·10⁵, no warm-up; the warm-up fitted whatever the drift test said) z read −1.8 to 2.1;
#: on 20 warm-ups of 0.012·e^{−t/T} (T 40–1500 s, 100 Hz–1 kHz × 10⁵–10⁶, with and without a 6.2 Hz line) 10–19,
#: but for the two at 1 kHz with T 100 s and the line, 3.0 and 3.6 (the line bends the noise fit they are weighed
#: against).
HELDOUT_Z = 4.0


def warmup_heldout(y: np.ndarray, fs: float, noise: dict, T: float, ramp: bool, n_blocks: int = BLOCKS) -> dict:
    """The held-out test in time of a warm-up of time constant ``T`` (s): ``ratio`` < 1 when the warm-up fitted on
    one part of the record's block means predicts the other part's, both ways, beyond what the noise ``noise``
    ({"N", "B", "K"}, base form; R is the free ``ramp`` column) itself predicts there.

    The parts interleave groups of consecutive block means no longer than T/2 (at least
    :data:`HELDOUT_MIN_GROUPS` groups), each part with a block at the record's start (:func:`_interleave`):
    within a group the warm-up falls by at most e^{−1/2}, so both parts see its whole shape, from its start.
    Alternate blocks of an eighth of the record (the Allan curve's held-out split) put a warm-up shorter than a
    block into one part alone: the other part's fit has little to go on (accelerometer-like noise +
    0.012·e^{−t/400 s} in 5000 s: a 0.0086, T 528 s on the part without the first 625 s; on other seeds and rates
    T from 25 to 5000 s), and no τ where the two parts' curves agree holds it.

    The score is the held-out part's conditional Gaussian χ² given the held-in part — its block means less the
    model's mean (c (+ r·t) (+ a·e^{−t/T}), fitted by GLS on the held-in part, the warm-up's T profiled there),
    less what the noise's covariance predicts of them from the held-in part's residuals (kriging), weighed by the
    conditional covariance — with the warm-up over the same without it. Fine interleaving lets the two parts
    share a random walk's wander, so a warm-up fitted to that wander would predict the held-out part *in plain
    variance*; but under the noise model the held-out part's conditional residual is independent of everything
    in the held-in part, so a component fitted on the held-in part to the noise alone only adds to the
    held-out χ² (its expectation rises by the component's own conditional size): the wander is what the noise's
    covariance already predicts from the neighbouring blocks, and only what it cannot — the warm-up's shape —
    lowers the ratio. Returns ``ratio``, the groups' length ``group_s`` (s), and per way the held-in fit
    (``fits``: amplitude, T)."""
    b, edges = _blocks(y, fs, n_blocks)
    pairs = _pairs(edges)
    tb = 0.5 * (pairs[:, 0] + pairs[:, 1])
    length = y.size / fs
    nb = b.size
    per_group = max(1, min(int(0.5 * T / (edges[1] - edges[0])), nb // HELDOUT_MIN_GROUPS))
    parity = _interleave(nb, per_group)
    cov = _cov_of_blocks(pairs, _slow_free(noise))
    sums = np.zeros(4)  # Σ|e|², Σ δ·e, Σ|δ|², held-out block means, over both ways
    fits = []
    for p in (0, 1):
        h, o = parity == p, parity != p
        fit_h = gls_warmup(b[h], tb[h], cov[np.ix_(h, h)], length, ramp=ramp)
        fits.append((fit_h["amplitude"], fit_h["T"]))
        e, d = _conditional(b, tb, cov, h, o, ramp, np.exp(-tb / fit_h["T"]))
        sums += (float(e @ e), float(d @ e), float(d @ d), e.size)
    ratio = (sums[0] - 2.0 * sums[1] + sums[2]) / sums[0] if sums[0] > 0 else math.inf
    # in the residuals' own scale (Σ|e|²/n, 1 under the noise model): a misfit noise level (a line's bump taken
    # by the five terms' N) would otherwise scale z, where the ratio is free of it
    z = sums[1] / math.sqrt(sums[2] * sums[0] / sums[3]) if sums[0] > 0 and sums[2] > 0 else 0.0
    return {"ratio": ratio, "z": z, "group_s": per_group * float(edges[1] - edges[0]), "fits": fits}


def _interleave(nb: int, per_group: int) -> np.ndarray:
    """The part (0, 1) of each of ``nb`` block means: the first block in part 0, the second in part 1, then
    alternate groups of ``per_group`` consecutive blocks — each part holds a block at the record's start, so
    neither extrapolates the warm-up back to where it is largest (a part whose first block is T/2 in trades a
    for T there: ADIS16405 run 3 x + 0.2·e^{−t/600 s}, one part's fit a 0.49, T 219 s, held-out ratio 1.54).
    Finer groups at the start (growing from one block) lose what they hold of the warm-up to the noise's own
    prediction from the neighbouring blocks (1 kHz × 10⁶ with T 100 s: z 5.8 → 2.3)."""
    parity = np.zeros(nb, dtype=np.int64)
    parity[1:2] = 1
    parity[2:] = (np.arange(max(nb - 2, 0)) // per_group) % 2  # the third block starts a group of part 0
    return parity


def _conditional(b, tb, cov, h, o, ramp: bool, shape) -> tuple[np.ndarray, np.ndarray]:
    """The held-out block means ``b[o]``' conditional residual given the held-in ``b[h]`` without the warm-up,
    whitened by its conditional covariance (``e``), and what the warm-up ``shape`` fitted on the held-in part
    takes off it (``δ``: the residual with it is e − δ). The mean c (+ r·t) (+ a·shape) by GLS on the held-in
    part; the noise's prediction of the held-out residuals from the held-in ones C_oh·C_hh⁻¹."""
    c_hh, c_oh = cov[np.ix_(h, h)], cov[np.ix_(o, h)]
    chol = _cholesky(c_hh)
    gain = solve_triangular(chol.T, solve_triangular(chol, c_oh.T, lower=True), lower=False).T
    s_chol = _cholesky(cov[np.ix_(o, o)] - gain @ c_oh.T)
    res = []
    for warm in (False, True):
        x = np.column_stack([np.ones_like(tb)] + ([tb - tb.mean()] if ramp else []) + ([shape] if warm else []))
        wx, wb = solve_triangular(chol, x[h], lower=True), solve_triangular(chol, b[h], lower=True)
        mu = x @ np.linalg.lstsq(wx, wb, rcond=None)[0]
        res.append(solve_triangular(s_chol, (b[o] - mu[o]) - gain @ (b[h] - mu[h]), lower=True))
    return res[0], res[0] - res[1]


def warmup_crlb(
    length: float, amplitude: float, T: float, noise: dict, n_blocks: int = BLOCKS, ramp: bool | None = None
) -> dict:
    """Cramér–Rao bound of a warm-up c + a·e^{−t/T} in a record of ``length`` s with the noise terms ``noise``
    ({"N", "B", "K", "R"}, base form): the inverse Fisher information of (c, a, T) from ``n_blocks`` block means,
    J·C⁻¹·Jᵀ with J the block means' derivatives (exact block averages) and C :func:`block_covariance`.

    ``ramp``: the rate ramp R·t is a deterministic slope of unknown size (the simulator's, and an unknown
    sensor's), a free column in J (True), or known (False: left out); by default a free column when
    ``noise["R"] > 0``. R never enters C here. The noise terms are taken as known: for Gaussian noise the
    Fisher information of the mean's parameters and of the covariance's is block-diagonal, so estimating the
    noise does not raise the bound (it raises an estimator's error above it on one record).

    Returns ``T_sd``, ``amplitude_sd`` (the 1-σ bounds for any unbiased estimator) and ``T_rel``,
    ``amplitude_rel`` (over T and |a|); with a T error that is normal, the median |T error| is 0.674·T_rel.

    Examples
    --------
    >>> from allanite.model.warmup import warmup_crlb
    >>> b = warmup_crlb(1e4, 0.08, 1500.0, {"N": 0.0415, "B": 0.00714})  # ADIS-like white + flicker
    >>> round(b["T_rel"], 2)
    0.28
    """
    e = np.linspace(0.0, float(length), max(3, int(n_blocks)) + 1)
    s0, s1 = e[:-1], e[1:]
    w = s1 - s0
    x0, x1 = np.exp(-s0 / T), np.exp(-s1 / T)
    cols = [np.ones(w.size), T * (x0 - x1) / w, amplitude * (x0 * (s0 + T) - x1 * (s1 + T)) / (T * w)]
    if ramp is None:
        ramp = noise.get("R", 0.0) > 0
    if ramp:
        cols.append(0.5 * (s0 + s1))
    jac = np.column_stack(cols)
    chol = _cholesky(_cov_of_blocks(_pairs(e), _slow_free(noise)))
    wj = solve_triangular(chol, jac, lower=True)
    cov = np.linalg.inv(wj.T @ wj)
    t_sd, a_sd = math.sqrt(cov[2, 2]), math.sqrt(cov[1, 1])
    return {"T_sd": t_sd, "amplitude_sd": a_sd, "T_rel": t_sd / T, "amplitude_rel": a_sd / abs(amplitude)}


def _has_ramp(noise: dict) -> bool:
    return noise.get("R", 0.0) > 0


def _slow_free(noise: dict) -> dict:
    """The noise terms without R: a rate ramp is a deterministic slope of unknown size, fitted as a free column
    (as a random slope of variance R², the GLS shrinks it towards zero and the warm-up takes the rest: on 10 Hz
    records of the ADIS run 4 x model, T's mean error −34 %, −6 % with the free column)."""
    return {k: v for k, v in noise.items() if k != "R"}


def _pairs(edges: np.ndarray) -> np.ndarray:
    e = np.asarray(edges, dtype=np.float64)
    return np.column_stack([e[:-1], e[1:]])


def _cov_of_blocks(edges: np.ndarray, noise: dict) -> np.ndarray:
    """:func:`block_covariance` for blocks [edges[i, 0], edges[i, 1]) that need not touch (a held-in part)."""
    s0, s1 = edges[:, 0], edges[:, 1]
    w = s1 - s0
    cov = np.diag(noise.get("N", 0.0) ** 2 / w)
    k, b, r = noise.get("K", 0.0), noise.get("B", 0.0), noise.get("R", 0.0)
    if k > 0:
        rw = np.minimum.outer(0.5 * (s0 + s1), 0.5 * (s0 + s1))
        rw[np.diag_indices(w.size)] = s0 + w / 3.0
        cov += k * k * rw
    if b > 0:
        cov += b * b * _flicker(s0, s1, w, s1[-1] - s0[0])
    if r > 0:
        tc = 0.5 * (s0 + s1)
        tc = tc - tc.mean()
        cov += r * r * np.outer(tc, tc)
    return cov
