from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

#: The package version (the Rust crates' version, Cargo.toml).
__version__: str

def davar(
    columns: Sequence[npt.NDArray[np.float64]],
    window: int,
    hop: int,
    ms: Sequence[int],
    estimator: str,
    method: str,
    workers: int,
) -> npt.NDArray[np.float64]:
    """Allan variance of every window at every m for every axis: shape (axes, len(ms), windows)."""

def davar_ranged(
    columns: Sequence[npt.NDArray[np.float64]],
    window: int,
    hop: int,
    ms: Sequence[int],
    estimator: str,
    method: str,
    workers: int,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """``davar`` and each (axis, m) row's range: shape (axes, len(ms), 3) — largest value, smallest value,
    1.0 where some value is not finite."""

def fit_windows(
    avar: npt.NDArray[np.float64],
    design: npt.NDArray[np.float64],
    nu_terms: npt.NDArray[np.float64],
    start_col: int,
    irls_iter: int,
    max_iter: int,
    gls_tol: float,
    irls_rtol: float,
    rho: Sequence[float],
    log2_tau: Sequence[float],
    s_blk: npt.NDArray[np.float64] | None,
    t_blk: npt.NDArray[np.float64] | None,
    stoch: Sequence[int],
    ramp: int | None,
    workers: int,
) -> npt.NDArray[np.float64]:
    """The noise fit of every window (rows of ``avar``): (windows, terms + terms² + 3) — θ, covariance,
    χ², iterations, status (0 fitted; else refit the window in Python)."""

def irls_curves(
    design: npt.NDArray[np.float64],
    nu_cols: npt.NDArray[np.float64],
    y: npt.NDArray[np.float64],
    nu0: npt.NDArray[np.float64],
    fixed: npt.NDArray[np.float64],
    max_iter: int,
    floor: float,
    rtol: float,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """refine's reweighted NNLS of the curve y (n τ) on every design (designs, n, k) with the EDF columns
    nu_cols, ν from nu0; fixed[k] a held coefficient or NaN: (θ (designs, k), ν (designs, n)). ValueError
    for a non-finite weighted problem, RuntimeError when the NNLS does not settle (as scipy's nnls)."""

def whittle_noise(
    shapes: npt.NDArray[np.float64],
    power: npt.NDArray[np.float64],
    root_m: npt.NDArray[np.float64],
    s_start: npt.NDArray[np.float64],
    max_iter: int,
    rtol: float,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """The Whittle noise fit's reweighted NNLS: non-negative amounts of shapes (bands, k) fitted to the band
    powers, weights root_m/S from the level s_start on, until S moves by less than rtol: (amounts (k), S
    (bands)). ValueError for a non-finite weighted problem, RuntimeError when the NNLS does not settle."""

def davar_part(
    columns: Sequence[npt.NDArray[np.float64]],
    window: int,
    hop: int,
    ms: Sequence[int],
    estimator: str,
    method: str,
    workers: int,
    mus: Sequence[float],
    first_window: int,
    n_windows: int,
) -> npt.NDArray[np.float64]:
    """davar of windows first_window.. of a record of n_windows windows, from its samples from
    first_window·hop on, centred on the record's means: the whole-record values (bit for bit where the
    record's call streams, and from a part_grid start on its phase path; to a few ε elsewhere)."""

def part_grid(n: int, n_axes: int, window: int, hop: int, estimator: str, method: str) -> int:
    """Samples between the cuts of a record into davar_part parts that give the whole call bit for bit: the
    hop where the call streams, a phase segment on its phase path, a chunk of terms on its chunked path
    (windows over 2^21 samples on records over 2^26 samples × axes, hops ≥ 64)."""

def compensated_sums(
    columns: Sequence[npt.NDArray[np.float64]],
    state: Sequence[tuple[float, float]],
) -> list[tuple[float, float]]:
    """Neumaier's compensated sum of each column continued from state[(sum, compensation) per axis]."""

def block_lag1_sums(
    x: npt.NDArray[np.float64],
    mu: float,
    ms: Sequence[int],
    dmax: int,
    workers: int,
) -> npt.NDArray[np.float64]:
    """(len(ms), dmax + 1, 5): Σw, Σw², Σ w_j w_(j+1), first and last w of the block averages of x − mu
    at each m and their differences up to dmax (NaN where empty)."""

def parse_decimal_table(
    text: bytes,
    offset: int,
    delimiter: str | None,
    ncols: int,
    cols: Sequence[int],
) -> npt.NDArray[np.float64] | None:
    """Columns cols (sorted) of the data lines of text[offset:], (rows, len(cols)); None off the fast path."""

def angle_term_sums(
    blocks: Sequence[npt.NDArray[np.float64]],
    starts: Sequence[int],
    off_w: Sequence[Sequence[int]],
    off_r: Sequence[Sequence[float]],
    q_exp: int,
    plan: Sequence[tuple[int, int, int]],
    classic: bool,
    workers: int,
) -> npt.NDArray[np.float64]:
    """Σ (X[i+2m] − 2X[i+m] + X[i])² in quanta² per plan item and axis, X the exact angle of the blocks."""

def davar_hann(
    columns: Sequence[npt.NDArray[np.float64]],
    window: int,
    hop: int,
    ms: Sequence[int],
    method: str,
    workers: int,
) -> npt.NDArray[np.float64]:
    """Hann-weighted overlapping Allan variance of every window: shape (axes, len(ms), windows)."""

def theo1_static(
    columns: Sequence[npt.NDArray[np.float64]],
    ms: Sequence[int],
    workers: int,
) -> npt.NDArray[np.float64]:
    """Theo1 of each whole rate record at every even m (phase: M + 1 points): shape (axes, len(ms))."""

def theo1_dynamic(
    columns: Sequence[npt.NDArray[np.float64]],
    window: int,
    hop: int,
    ms: Sequence[int],
    workers: int,
) -> npt.NDArray[np.float64]:
    """Theo1 of every sliding window at every even m: shape (axes, len(ms), windows)."""

def deviation_static(
    columns: Sequence[npt.NDArray[np.float64]],
    ms: Sequence[int],
    estimator: str,
    workers: int,
) -> npt.NDArray[np.float64]:
    """'mvar' | 'hvar' | 'ohvar' | 'totvar' | 'mtotvar' | 'htotvar' of each whole rate record, as a
    variance for τ0 = 1 (no bias correction): shape (axes, len(ms)). m ranges (M rate samples):
    mvar, mtotvar 1..=(M+1)//3; hvar, ohvar, htotvar 1..=M//3; totvar 1..=M."""

def ttotvar_static(
    columns: Sequence[npt.NDArray[np.float64]],
    ms: Sequence[int],
    tau0: float,
    workers: int,
) -> npt.NDArray[np.float64]:
    """Time total variance (m·tau0)²/3 · MTOTVAR: shape (axes, len(ms))."""

def deviation_gaps(
    columns: Sequence[npt.NDArray[np.float64]],
    ms: Sequence[int],
    estimator: str,
    workers: int,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]:
    """Gap-aware 'oavar' | 'avar' | 'mvar' | 'ohvar' | 'hvar' | 'totvar' | 'mtotvar' | 'htotvar' (NaN = missing
    sample): (values, complete-term counts), each of shape (axes, len(ms)); a τ with no complete term gives NaN
    and 0."""

def deviation_gaps_dynamic(
    columns: Sequence[npt.NDArray[np.float64]],
    window: int,
    hop: int,
    ms: Sequence[int],
    estimator: str,
    workers: int,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]:
    """Gap-aware 'oavar' | 'ohvar' of every sliding window: (values, complete-term counts), each of shape
    (axes, len(ms), windows); a window with no complete term at some m gives NaN and 0 there."""

def tie_gaps(
    phases: Sequence[npt.NDArray[np.float64]],
    gaps: Sequence[npt.NDArray[np.uint64]],
    ms: Sequence[int],
    estimator: str,
    workers: int,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]:
    """Gap-aware 'mtie' | 'tierms' of phase records with the prefix counts of missing rate samples (length N):
    (values, kept windows), each of shape (axes, len(ms))."""

def ohvar_dynamic(
    columns: Sequence[npt.NDArray[np.float64]],
    window: int,
    hop: int,
    ms: Sequence[int],
    workers: int,
) -> npt.NDArray[np.float64]:
    """Overlapping Hadamard variance of every sliding window: shape (axes, len(ms), windows)."""

def mtie_phase(
    columns: Sequence[npt.NDArray[np.float64]],
    ms: Sequence[int],
    workers: int,
) -> npt.NDArray[np.float64]:
    """MTIE of each phase record (windows of m + 1 points, 1 ≤ m ≤ N − 1): shape (axes, len(ms))."""

def tierms_phase(
    columns: Sequence[npt.NDArray[np.float64]],
    ms: Sequence[int],
    workers: int,
) -> npt.NDArray[np.float64]:
    """TIE rms of each phase record (1 ≤ m ≤ N − 1): shape (axes, len(ms))."""

def pvar_phase(
    phase: npt.NDArray[np.float64], ms: Sequence[int], workers: int
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]:
    """Parabolic-variance term sums Σ u_i² and counts N − 2m of a phase record at every m ≥ 2."""

def allan_covariance_phase(
    phase1: npt.NDArray[np.float64], phase2: npt.NDArray[np.float64], ms: Sequence[int], workers: int
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]:
    """Σ Δ²x1·Δ²x2 over the N − 2m overlapping second differences of two phase records, and counts."""

def oavar_phase_gaps(
    phase: npt.NDArray[np.float64], ms: Sequence[int], workers: int
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]:
    """Σ (Δ²x)² over the overlapping second differences with no NaN point, and their counts."""

def phase_bins(
    parts: Sequence[npt.NDArray[np.float64]],
    u: npt.NDArray[np.float64],
    m_bins: int,
    seg: npt.NDArray[np.int64] | None,
    n_seg: int,
    ph: npt.NDArray[np.float64] | None = None,
) -> list[npt.NDArray[np.float64]]:
    """Each part (or y·Re ph, y·(−Im ph) of the one part y with ph) spread linearly onto n_seg × m_bins phase bins."""

def add_waveform(
    out: npt.NDArray[np.float64],
    u: npt.NDArray[np.float64],
    wave: npt.NDArray[np.float64],
    ph: npt.NDArray[np.float64] | None,
) -> None:
    """out += Re[wave interpolated at the phases u (× the phasors ph)]; complex arrays as interleaved float64."""

def lattice_bins(
    y: npt.NDArray[np.float64],
    u: npt.NDArray[np.float64],
    m_bins: int,
    seg: npt.NDArray[np.int64] | None,
    n_seg: int,
    idx: npt.NDArray[np.int64],
    blocks: npt.NDArray[np.float64],
    offsets: npt.NDArray[np.float64],
    k0: int,
    power: int,
    conj: bool,
) -> list[npt.NDArray[np.float64]]:
    """The bins of y·Re ph and y·(−Im ph), the phasors ph = (blocks[idx // B − k0]·offsets[idx % B])^power (conjugated
    with conj; B = len(offsets) a power of two; complex tables as interleaved float64) made per sample."""

def add_lattice_waveform(
    out: npt.NDArray[np.float64],
    u: npt.NDArray[np.float64],
    wave: npt.NDArray[np.float64],
    idx: npt.NDArray[np.int64],
    blocks: npt.NDArray[np.float64],
    offsets: npt.NDArray[np.float64],
    k0: int,
    power: int,
    conj: bool,
) -> None:
    """:func:`add_waveform` with the phasors of :func:`lattice_bins` made per sample."""

class StreamingVariance:
    """Streaming "oavar", "ohvar" or "tvar" of a growing phase record (values for τ0 = 1)."""

    def __init__(self, kind: str, ms: Sequence[int], pending: Sequence[int]) -> None: ...
    def push(self, x: float) -> None: ...
    def extend(self, xs: npt.NDArray[np.float64]) -> None: ...
    def add_factor(self, m: int) -> None: ...
    def factors(self) -> list[int]: ...
    def counts(self) -> list[int]: ...
    def values(self) -> npt.NDArray[np.float64]: ...
    def phase(self) -> npt.NDArray[np.float64]: ...
    def __len__(self) -> int: ...
