"""The package's structure holds: imports run one way, no circles, no private names across modules.

Read from the source (AST), so a violation fails here before anyone meets it as an import error or
a tangle. The layers, bottom up (a module may import only from its own layer or below):

    0  errors, _core                       the exceptions; the Rust extension
    1  units, _validate, _progress,        shared checks and units; progress bars of long calls; reading a
       _mapped, _blas, _scoped             memory-mapped record through its file; OpenBLAS on one thread;
                                           a context variable set within a block
    2  estimators.*, io.*                  the registry and its entries, EDF; the readers
    3  plot, results, _display             figures; result objects (EDF sits below them); notebook HTML
    4  analysis, simulation, datasets, _reference
    5  model.*, forecast, compat.*         terms, covariance, fit, effects, refine; GM(1,1) forecasts;
                                           the allantools-compatible front door (whose opt-in alias
                                           install_as_allantools alone may write sys.modules)
    6  report.*
    7  cli, _cli_*, __main__, __init__, dask.* allanite.dask: arrays larger than memory, fleets (never imported by allanite)
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import allanite

PACKAGE = Path(allanite.__file__).parent

LAYERS = {
    "errors": 0,
    "_core": 0,
    "units": 1,
    "_validate": 1,
    "_progress": 1,
    "_mapped": 1,
    "_dist": 1,
    "_blas": 1,
    "_scoped": 1,
    "estimators": 2,
    "io": 2,
    "plot": 3,
    "results": 3,
    "_display": 3,
    "analysis": 4,
    "simulation": 4,
    "datasets": 4,
    "_reference": 4,
    "wavelet": 4,
    "model": 5,
    "forecast": 5,
    "compat": 5,
    "kalibr": 6,
    "combination": 5,
    "report": 6,
    "cli": 7,
    "_cli_options": 7,
    "_cli_columns": 7,
    "dask": 7,
    "__main__": 7,
    "__init__": 7,
}


def _modules() -> dict[str, Path]:
    out = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__" and len(parts) > 1:
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


MODULES = _modules()
#: Compiled modules of the package (no source to read): the Rust core.
EXTENSIONS = {"_core"}


def _resolve(module: str, node: ast.ImportFrom) -> str | None:
    """The in-package name (dotted, '' for the package itself) an ``from … import`` refers to, or None
    when it is outside the package."""
    if node.level == 0:
        name = node.module or ""
        if name == "allanite":
            return ""
        return name[len("allanite.") :] if name.startswith("allanite.") else None
    is_pkg = MODULES[module].name == "__init__.py"
    base = [] if module == "__init__" else (module.split(".") if is_pkg else module.split(".")[:-1])
    if node.level > 1:
        base = base[: len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def _imports(module: str):
    """(target module, names, line, top-level?) for every in-package import of ``module``."""
    tree = ast.parse(MODULES[module].read_text(encoding="utf-8"))
    top = {id(n) for n in tree.body}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            target = _resolve(module, node)
            if target is None:
                continue
            names = []
            for a in node.names:
                sub = f"{target}.{a.name}" if target else a.name
                if sub in MODULES or sub in EXTENSIONS:  # "from . import x": the name is a module
                    yield sub, [], node.lineno, id(node) in top
                else:
                    names.append(a.name)
            if names:
                yield (target or "__init__"), names, node.lineno, id(node) in top
        elif isinstance(node, ast.Import):
            for a in node.names:
                if a.name.startswith("allanite."):
                    yield a.name[len("allanite.") :], [], node.lineno, id(node) in top


def _layer(module: str) -> int:
    return LAYERS[module.split(".")[0]]


def test_every_module_has_a_layer():
    assert sorted(m for m in MODULES if m.split(".")[0] not in LAYERS) == []


@pytest.mark.parametrize("module", sorted(MODULES))
def test_imports_run_one_way(module):
    up = [(t, line) for t, _, line, _ in _imports(module) if _layer(t) > _layer(module)]
    assert up == [], f"{module} imports upward: {up}"


#: Inside ``model``, bottom up: a model module imports only model modules of a lower rank. The registries of
#: terms and effects and the covariance; the fit and the tracing tools; then refine's house — its false-alarm
#: budget, the weighted fit with effects, the errors in-sample and held out, the curve test and the result,
#: refine's inputs checked, the proposals per domain (curve candidates, removals in time, change points), the loop, the package.
MODEL_RANKS = {
    "model._recent": -1,
    "model._null_records": -0.5,  # the checks' null records, their flicker remembered (simulation, _recent)
    "model._chunked": -1,  # record-length passes a chunk at a time (numpy, scipy only)
    "model._medians": -1,  # medians along an axis by one sort (numpy only)
    "model._welch_spread": -1,  # Welch segments' spread per band: the line search's dof (numpy only)
    "model._robust_scale": -1,  # the differences' robust scale, on a lattice and local (numpy, scipy only)
    "model._rfft": -0.5,  # the channel regression's transforms, remembered by content
    "model._shaped": -0.5,  # noise-shaped (sigma-delta) quantisation's exact Allan variance (numpy only)
    "model._sinc": -0.5,  # the sinc^k (CIC) roll-off's autocorrelation and cutoff (numpy only)
    "model._declared": -0.5,  # a user-declared filter (FIR taps, IIR b, a) as an exact bandwidth kind (numpy, scipy)
    "model._sharp": -0.5,  # the sharp rippled bandwidth kinds' designs (elliptic, fixed order and stop band; scipy)
    "model._signatures": -0.25,  # the effects' Allan-variance signatures: filter kinds, sinusoid, resonance, drift
    "model._counter": -0.5,  # a delta-angle counter's exact Q column and the record read as one (numpy, scipy only)
    "model._quantiser": -0.4,  # a rate quantised at the output: its error's exact floor column (on _counter's lattice)
    "model._batched": 0,
    "model._chi2_draws": 0,
    "model._covariance": 0,
    "model._nnls": -0.5,  # SciPy's Lawson–Hanson routine without its wrapper (numpy, scipy only)
    "model.terms": 0,
    "model.effects": 0,
    "model.linefit": 0,
    "model.lines": 0,
    "model.outliers": 0,
    "model.telegraph": 0,  # random telegraph noise: its Allan variance, kurtosis test and two-level fit
    "model.noise_level": 0,
    "model._slowfit": 0.25,  # the slow-line test's noise fits: REML and ML deviances with their gradients (numpy, scipy)
    "model.slowline": 0.5,  # a line of few cycles tested in time under red noise (numpy, scipy only)
    "model.periodic": 1,
    "model.template": 0,
    "model.wander": 0,  # a line family's wandering fundamental tracked (numpy, scipy only)
    # fit's parts, between the registries and fit itself: the one-curve solver (and it in the core), the result
    # objects, the windows
    "model._fitcore": 0.5,
    "model._tauselect": 0,
    "model._gapfit": 0,  # a gapped result made ready for fit: its usable τ and each τ's share of terms kept
    "model._corefit": 0.6,
    "model._fitresult": 0.7,
    "model._dynamicfit": 0.9,
    "model._bound": 0,
    "model.fitting": 1,
    "model.tracing": 1,
    "model._whittle": 0,
    "model._edge": 0.3,  # the channel tests' exact null variance at the record's edges (on _whittle)
    "model._gls_cov": 0.6,  # a channel regression's interval covariance: restricted noise, exact score variance
    "model._lag": 0.5,  # a channel's first-order lag: its test and profile (on _whittle)
    "model._shares": 0,
    "model._regressors": 0.7,  # a channel regression's signal bands and regressors (on _whittle, _lag)
    "model._staircase": -0.5,  # a channel's form (quantum, hold) read from it, and the channel read back (numpy only)
    "model._coupling": 0.8,  # a channel regression's coupling test and optional terms
    "model._lag_time": 0.8,  # the lag a channel regression uses, in time: T, the fit beside it, both intervals
    "model._shape": 0.8,  # a coupling's shape beyond its kept terms: steps at the channel's quantiles (unexplained)
    "model.channels": 1,
    "model.timeframes": 2,
    "model.warmup": 2,
    "model.refinement.levels": 2,
    "model.refinement._slow_lines": 2,  # slow lines' least-squares component, for the drift's retest (on periodic)
    "model.refinement._irls": 2,
    "model.refinement._brent": 0,
    "model.refinement._channel_order": 0,  # the order a record's channels are regressed in: the strongest first
    "model.refinement._line_constancy": 0,
    "model.refinement._line_channel": 3.8,  # does a line whose amplitude changes follow a channel (its words)
    "model.refinement._line_gain": 3.9,  # an accepted line's amplitude following a channel, modelled (its option)
    "model.refinement._line_check": 4,
    "model.refinement._mean_step": 4,
    "model.refinement._mean_steps": 4,
    "model.refinement._quality": 4,
    "model.refinement.words": 3,
    "model.refinement._gapfill": 0,  # a record's NaN gaps checked and filled for refine(gaps="skip")
    "model.refinement._family_fold": 3,  # a periodic family and the sinusoids at its own lines: one effect
    "model.refinement._columns": 2.5,  # the curve and its columns (curvefit's lower half)
    "model.refinement._noisefit": 2.7,  # what a solution says of the terms; the NoiseFit it becomes
    "model.refinement.curvefit": 3,
    "model.refinement.scoring": 4,
    "model.refinement.calibrated": 5,
    "model.refinement.result": 5,
    "model.refinement._proposal": 5.2,  # a curve candidate's round, proposal and entry, and their shared helpers
    "model.refinement._bumps": 5.7,  # the curve candidates per domain (Gauss–Markov and resonance; bandwidth;
    "model.refinement._bandwidth": 5.7,  # sinusoid) and which proposal a step accepts: none imports another
    "model.refinement._sinusoid": 5.7,
    "model.refinement._shaped": 5.7,  # shaped quantisation (sigma-delta) beside them
    "model.refinement._choose": 5.7,
    "model.refinement.candidates": 6,
    "model.refinement._tracking": 5,  # a family's or a lone line's phase tracked, the held-out test in time
    "model.refinement._telegraph": 5.8,  # the telegraph removal's test, fit and evidence (removals' entry)
    "model.refinement._family_parts": 5.5,  # a periodic removal's params, folded waveform and lone-line sinusoid (removals' entry)
    "model.refinement.removals": 6,
    "model.refinement.changes": 6,
    # unexplained's parts, below missing (its spectral-line and channel checks, CHECKS): what a check is given;
    # the Allan curve's checks; the final samples' checks along the record (neither imports the other)
    "model.refinement._missing_context": 3.5,
    "model.refinement._curve_checks": 6.5,
    "model.refinement._time_checks": 6.5,
    "model.refinement._segments": 6.6,  # the change points' segments: their levels, the departures they carry
    "model.refinement._channel_shape": 6.5,  # the residual's dependence on a channel's value (on model._shape)
    "model.refinement._channel_follows": 6.5,  # an accepted line a channel carries (on _missing_context, curvefit)
    "model.refinement.missing": 7,
    "model.refinement._rolloff": 5.5,
    "model.refinement._notch": 5.6,  # a notch after the roll-off (on _rolloff; the bandwidth candidate's)
    "model.refinement._sharp": 5.6,  # the sharp rippled kinds' search (on _rolloff; the bandwidth candidate's)
    "model.refinement._inputs": 4.5,
    # refine's parts, below loop (its curve steps): the refinement under way and its chain; the removals in time
    # on it; the chain scored, the change points and the result on it (with what is missing: above missing)
    "model.refinement._run": 6.5,
    "model.refinement._in_time": 6.7,
    "model.refinement._final": 7.5,
    "model.refinement.loop": 8,
    "model.refinement": 9,
    "model": 10,
}
MODEL_MODULES = sorted(m for m in MODULES if m.split(".")[0] == "model")


def test_every_model_module_has_a_rank():
    assert sorted(m for m in MODEL_MODULES if m not in MODEL_RANKS) == []


@pytest.mark.parametrize("module", MODEL_MODULES)
def test_model_imports_run_one_way(module):
    own = MODEL_RANKS[module]
    # a package assembling its own submodules is not an import across ranks
    up = [
        (t, line)
        for t, _, line, _ in _imports(module)
        if t.split(".")[0] == "model" and not t.startswith(module + ".") and MODEL_RANKS.get(t, own + 1) >= own
    ]
    assert up == [], f"{module} imports model modules of its own rank or above: {up}"


#: report.build's parts, below it: the plan of window, hop and memory, and the optional sections. Neither imports
#: build (nor the report package, which assembles build), nor the other.
REPORT_BUILD_PARTS = ("report._plan", "report._sections")


@pytest.mark.parametrize("module", REPORT_BUILD_PARTS)
def test_report_build_parts_sit_below_it(module):
    up = [
        (t, line)
        for t, _, line, _ in _imports(module)
        if t in ("report", "report.build") or (t in REPORT_BUILD_PARTS and t != module)
    ]
    assert up == [], f"{module} imports report.build, the report package or its sibling part: {up}"


@pytest.mark.parametrize("module", sorted(MODULES))
def test_no_private_names_across_modules(module):
    bad = [
        (t, n, line)
        for t, names, line, _ in _imports(module)
        for n in names
        if n.startswith("_") and n != "__version__" and t != module
    ]
    assert bad == [], f"{module} takes private names of other modules: {bad}"


#: The exceptions, each in one function: allanite.compat's opt-in alias writes sys.modules so that `import
#: allantools` gives allanite.compat — called by the user, never on import (docs/compat.md); allanite._dist loads
#: scipy.special's compiled ufuncs without the package (~0.2 s of CPU less at the first interval) under a stand-in
#: package it takes out of sys.modules again, with every entry the load added (tests/test_lazy_imports.py).
SYS_MODULES_ALLOWED = {"compat._alias": "install_as_allantools", "_dist": "_ufuncs_alone"}


def _sys_modules_uses(tree: ast.Module) -> list[tuple[str | None, int]]:
    """(enclosing top-level function or None, line) of every ``sys.modules`` in the module's code."""
    out = []
    for top in tree.body:
        owner = top.name if isinstance(top, (ast.FunctionDef, ast.AsyncFunctionDef)) else None
        for node in ast.walk(top):
            if isinstance(node, ast.Attribute) and node.attr == "modules":
                if isinstance(node.value, ast.Name) and node.value.id == "sys":
                    out.append((owner, node.lineno))
    return out


@pytest.mark.parametrize("module", sorted(MODULES))
def test_no_reaching_through_sys_modules(module):
    text = MODULES[module].read_text(encoding="utf-8")
    if module not in SYS_MODULES_ALLOWED:
        assert "sys.modules" not in text
        return
    uses = _sys_modules_uses(ast.parse(text))
    assert uses, f"{module} was allowed sys.modules for {SYS_MODULES_ALLOWED[module]} but no longer uses it"
    assert all(owner == SYS_MODULES_ALLOWED[module] for owner, _ in uses), (module, uses)


def test_the_sys_modules_exception_is_checked():
    """The amended rule catches a use outside the allowed function (and counts the allowed one)."""
    bad = ast.parse("import sys\ndef install_as_allantools():\n    sys.modules['a'] = 1\nX = sys.modules\n")
    assert _sys_modules_uses(bad) == [("install_as_allantools", 3), (None, 4)]


def test_no_import_cycles():
    graph = {m: {t for t, _, _, top in _imports(m) if top and t != m} for m in MODULES}
    # a package's __init__ importing its own submodules is the package being assembled, not a circle
    for m in graph:
        graph[m] = {t for t in graph[m] if not t.startswith(m + ".")}
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(m):
        state[m] = 1
        stack.append(m)
        for t in graph.get(m, ()):
            if state.get(t) == 1:
                raise AssertionError("import circle: " + " → ".join(stack[stack.index(t) :] + [t]))
            if t not in state:
                visit(t)
        stack.pop()
        state[m] = 2

    for m in graph:
        if m not in state:
            visit(m)


@pytest.mark.parametrize("module", sorted(MODULES))
def test_no_function_shares_a_name_with_a_sibling_module(module):
    siblings = {p.stem for p in MODULES[module].parent.glob("*.py")} | {
        p.name for p in MODULES[module].parent.iterdir() if p.is_dir() and (p / "__init__.py").exists()
    }
    tree = ast.parse(MODULES[module].read_text(encoding="utf-8"))
    clash = [n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef)) and n.name in siblings]
    assert clash == [], f"{module} defines {clash}, which are also module names beside it"


def test_the_public_api_is_pinned():
    """Every name the package exports, and the parameters of each public function (new keyword
    arguments may be added at the end; nothing may disappear or change kind)."""
    import inspect

    assert sorted(allanite.__all__) == sorted(PINNED)
    for name, params in PINNED.items():
        obj = getattr(allanite, name)
        if params is None:
            continue
        sig = inspect.signature(obj)
        got = [(p.name, p.kind.name) for p in sig.parameters.values()]
        assert got[: len(params)] == params, f"allanite.{name}{sig}"
        assert all(p.kind.name in ("KEYWORD_ONLY", "VAR_KEYWORD") for p in list(sig.parameters.values())[len(params) :])


P, K = "POSITIONAL_OR_KEYWORD", "KEYWORD_ONLY"
PINNED = {
    "avar": [
        ("x", P),
        ("fs", P),
        ("input", K),
        ("taus", K),
        ("estimator", K),
        ("workers", K),
        ("kf_rule", K),
        ("decimate", K),
    ],
    "davar": [
        ("x", P),
        ("fs", P),
        ("window", K),
        ("hop", K),
        ("taus", K),
        ("method", K),
        ("estimator", K),
        ("input", K),
        ("workers", K),
        ("max_memory", K),
        ("kf_rule", K),
    ],
    "tau_grid": [("n", P), ("fs", P), ("kind", P), ("growth", K), ("points", K), ("tau_min", K), ("m_max", K)],
    "default_record": [("seed", P)],
    "simulate": None,
    "read_log": None,
    "Log": None,
    "fit": [
        ("result", P),
        ("terms", K),
        ("unit", K),
        ("confidence", K),
        ("thin", K),
        ("tau_range", K),
        ("max_iter", K),
        ("progress", K),
    ],
    "information_bound": [("n", P), ("fs", P), ("Q", K), ("N", K), ("B", K), ("K", K)],
    "NoiseFit": None,
    "CoefficientSeries": None,
    "frames": [
        ("x", P),
        ("fs", P),
        ("frame", P),
        ("unit", K),
        ("input", K),
        ("terms", K),
        ("confidence", K),
        ("taus", K),
        ("tau_range", K),
        ("thin", K),
        ("workers", K),
        ("progress", K),
    ],
    "TimeFrames": None,
    "refine": [
        ("x_or_result", P),
        ("fs", P),
        ("start", K),
        ("candidates", K),
        ("unit", K),
        ("input", K),
        ("tau_range", K),
        ("truth", K),
        ("confidence", K),
        ("points", K),
        ("axis", K),
    ],
    "Refinement": None,
    "to_kalibr": [
        ("path", P),
        ("gyro", K),
        ("accel", K),
        ("update_rate", K),
        ("rostopic", K),
        ("aggregate", K),
    ],
    "confidence_intervals": [
        ("result", P),
        ("x", P),
        ("confidence", K),
        ("alpha", K),
        ("edf_method", K),
        ("chi2", K),
        ("b1_n", K),
    ],
    "identify_alpha": [("x", P), ("m", P), ("input", K), ("estimator", K), ("method", K), ("b1_n", K)],
    "edf_greenhall": [("alpha", P), ("d", P), ("m", P), ("N", P), ("overlapping", P), ("modified", P)],
    "edf_sp1065": [("alpha", P), ("m", P), ("N", P), ("estimator", P)],
    "chi2_interval": [("variance", P), ("edf", P), ("confidence", P), ("method", K)],
    "AllanResult": None,
    "DynamicAllanResult": None,
    "AllaniteError": None,
    "InputError": None,
    "ParameterError": None,
    "MemoryBudgetError": None,
    "__version__": None,
    "wavelet_split": [
        ("x", P),
        ("fs", P),
        ("wavelet", K),
        ("level", K),
        ("bands", K),
        ("trend", K),
        ("trend_freq", K),
    ],
    "Split": None,
    "combine": [
        ("x", P),
        ("fs", P),
        ("window", K),
        ("hop", K),
        ("taus", K),
        ("split", K),
        ("low_taper", K),
        ("high_taper", K),
        ("terms", K),
        ("gauss_markov", K),
        ("unit", K),
        ("workers", K),
        ("progress", K),
    ],
    "Combination": None,
}
