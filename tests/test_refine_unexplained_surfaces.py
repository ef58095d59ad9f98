"""What the final model still misses is said on every surface (issue 29 item 4): ``Refinement.report()``, the
notebook display, ``allanite report``'s console, its HTML page and ``summary.json`` — with the region in τ (s)
and frequency (Hz) when a check finds something, and "passes" only when none does.

A sinusoid refined with ``candidates=("bandwidth",)`` (its own candidates left out) must leave a region near
1.3 Hz; a clean white + rate-random-walk record must pass. Short records (6·10⁴ samples) keep each test to a
few seconds.
"""

from __future__ import annotations

import html as html_mod
import json
import re

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import allanite  # noqa: E402
from allanite import cli  # noqa: E402
from allanite.model.refinement.words import describe_region, missing_sentences, passes_sentence  # noqa: E402
from allanite.report import build_report  # noqa: E402

FS, F_LINE = 100.0, 1.3


def _noise(n=60_000):
    return allanite.simulate(n, FS, N=2e-3, K=2e-5, seed=3)


def _with_line(n=60_000):
    t = np.arange(n) / FS
    return _noise(n) + 3e-3 * np.sin(2 * np.pi * F_LINE * t)


def _assert_region_at_the_line(entries):
    """Some entry's band holds the line and its τ range the τ where a 1.3 Hz line bends the curve."""
    hits = [e for e in entries if e["band_hz"] is not None and e["band_hz"][0] <= F_LINE <= e["band_hz"][1]]
    assert hits, entries
    for e in hits:
        lo, hi = e["tau_s"] if "tau_s" in e else e["tau"]
        assert 0.05 < lo <= hi < 3.0 and lo <= 0.5 / F_LINE * 2 and e["chi2_dof"] > 1.0


def test_words_of_a_region_and_of_a_pass():
    reg = {"tau": (0.2, 3.0), "band_hz": (0.1667, 2.5), "chi2_dof": 4.12, "what": "the Allan curve departs"}
    assert describe_region(reg) == "τ 0.20–3.0 s, ≈ 0.17–2.5 Hz: the Allan curve departs, χ²/dof 4.1 there"
    assert missing_sentences([reg], 0.05) == [f"The model still misses something at {describe_region(reg)}."]
    # curve-only input: no band; a NaN χ²/dof is left out, not printed
    bare = {"tau": (1.5, 1.5), "band_hz": None, "chi2_dof": float("nan"), "what": ""}
    assert describe_region(bare) == "τ 1.5 s"
    assert missing_sentences([], 0.05) == [passes_sentence(0.05)]
    assert "0.65 %" in passes_sentence(0.05) and "level 0.05" in passes_sentence(0.05)
    assert "0.13 %" in passes_sentence(0.01)


def test_report_and_notebook_say_what_a_refinement_misses():
    r = allanite.refine(
        _with_line(), FS, candidates=("bandwidth",), unit="deg/s", tau_range=(0.1, None), progress=False
    )
    assert r.found == [] and r.unexplained and r.level == 0.05
    _assert_region_at_the_line(r.unexplained)
    sentences = r.missing_sentences()
    assert len(sentences) == len(r.unexplained) and all(s.startswith("The model still misses") for s in sentences)
    md, page = r.report(), html_mod.unescape(r._repr_html_())
    for s in sentences:
        assert s in md and s in page
    for text in (md, page):
        assert "passes every calibrated check" not in text
        assert "the starting model fits" not in text
    assert "no candidate earned its parameters — but the model still misses something" in md


@pytest.mark.slow  # CLI surfaces: test_refine_unexplained_level.py, test_refine_quality.py
def test_cli_console_page_and_json_say_the_region(tmp_path, capsys):
    log, out = tmp_path / "line.npy", tmp_path / "out"
    np.save(log, _with_line())
    args = ["report", str(log), "--fs", "100", "--unit", "deg/s", "--window", "6000", "--hop", "3000", "--no-fit"]
    assert cli.main([*args, "--refine-candidates", "bandwidth", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    ax = summary["refinement"]["axes"][0]
    assert summary["refinement"]["tried"] == ["bandwidth"] and ax["steps"] == []
    _assert_region_at_the_line(ax["unexplained"])
    assert ax["still_missing"] == [f"The model still misses something at {e['text']}." for e in ax["unexplained"]]
    json.dumps(summary, allow_nan=False)  # numbers and null, never NaN
    for e in ax["unexplained"]:
        assert all(isinstance(v, float) for v in e["tau_s"]) and e["domain"] in ("allan", "psd")
    page = html_mod.unescape(re.sub(r"<[^>]+>", "", (out / "report.html").read_text(encoding="utf-8")))
    section = page[page.index("What the model still misses") :]
    for s in ax["still_missing"]:
        assert f"    {s}" in printed  # the console, under the axis
        assert s in section  # the page's section
    assert "passes every calibrated check" not in printed + page
    # a fleet's table (allanite batch --refine) takes the same words from summary.json
    fleet = pytest.importorskip("allanite.dask.fleet")
    (row,) = fleet._rows({"path": str(log), "out": str(out), "status": "ok", "error": None})
    assert row["effects"] == "" and row["still_missing"] == "; ".join(e["text"] for e in ax["unexplained"])


def test_cli_refine_candidates_unknown_name_is_a_usage_error(tmp_path, capsys):
    log = tmp_path / "g.npy"
    np.save(log, _noise(3_000))
    rc = cli.main(["report", str(log), "--fs", "100", "--refine-candidates", "bandwidth,sinus", "--out", str(tmp_path)])
    assert rc == 2
    assert re.search(
        r"unknown candidate effect 'sinus'; allowed: gauss_markov, sinusoid, bandwidth, .*outliers",
        capsys.readouterr().err,
    )
    with pytest.raises(allanite.AllaniteError, match="refine: unknown candidate effect 'drfit'"):
        build_report(_noise(3_000), FS, refine=("drift", "drfit"))


def test_a_clean_record_passes_on_every_surface():
    rep = build_report(_noise()[:, None], FS, unit="deg/s", refine=True, window=6_000, hop=3_000, fit=False)
    r = rep.refinements[0]
    assert r is not None and r.steps == [] and r.unexplained == []
    ax = rep.summary()["refinement"]["axes"][0]
    assert ax["unexplained"] == [] and ax["still_missing"] == [passes_sentence(0.05)]
    text, page = rep.text(), html_mod.unescape(rep.html({}))
    assert f"    {passes_sentence(0.05)}" in text
    assert passes_sentence(0.05) in page and passes_sentence(0.05) in r.report()
    assert "The model still misses something" not in text + page + r.report()
    assert "nothing added: the starting model passes every calibrated check" in html_mod.unescape(r._repr_html_())


def test_a_regions_chi2_dof_is_the_mean_z2_over_its_tau_ends_included():
    """Every check's entry takes χ²/dof over its τ region from one place (``curvefit.chi2_dof_between``): the
    region's ends are τ of the curve itself, so they are in, to 10⁻⁹ relative (a τ re-read from a float)."""
    from allanite.model.refinement.curvefit import chi2_dof_between

    tau = np.array([0.01, 0.02, 0.04, 0.08, 0.16])
    z = np.array([1.0, 2.0, 3.0, 4.0, 5.0])
    assert chi2_dof_between(tau, z, 0.02, 0.08) == pytest.approx((4 + 9 + 16) / 3)
    assert chi2_dof_between(tau, z, 0.02 * (1 + 5e-10), 0.08 * (1 - 5e-10)) == pytest.approx((4 + 9 + 16) / 3)
    assert chi2_dof_between(tau, z, 0.16, 0.16) == pytest.approx(25.0)
    assert np.isnan(chi2_dof_between(tau, z, 0.05, 0.07))


def test_the_passing_sentence_names_every_check_of_unexplained():
    """ "Passes every calibrated check (…)" lists what was checked: a check with a share of ``level`` and no
    words here would pass unsaid (the sentence once lacked the line and steps checks)."""
    from allanite.model.refinement.levels import UNEXPLAINED_SHARES

    words = {
        "allan": "the Allan-curve score test",
        "psd": "lines in the PSD",
        "line": "an accepted line's amplitude along the record",
        "time": "a drift",
        "mean": "steps of the mean",
        "steps": "steps of the mean",
        "level": "the noise level along the record",
        "channels": "the channels",
        "channel_shape": "the channels",
        "outliers": "outliers",
        "clipped": "clipped or repeated samples",
        "held": "clipped or repeated samples",
    }
    assert set(words) == set(UNEXPLAINED_SHARES)
    text = passes_sentence(0.05)
    assert [k for k, w in words.items() if w not in text] == []
    assert "two-sided GLS χ²" in text and "0.65 %" in text
