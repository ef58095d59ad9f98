"""The report page reads as written (issue 32 item 3): no template blanks, times along the record in
seconds to the sample (h:mm:ss on long records), the same words on the console and the page, every
figure written shown (the refinement's too), no empty header row, "1 axis", tables that scroll, and
the coefficients over time summarised over the windows (median of all, an unresolved window at 0; min, max and
count of the windows that resolve them).
"""

from __future__ import annotations

import json
import re
from html.parser import HTMLParser

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import allanite  # noqa: E402
from allanite.model.effects import EFFECTS, format_param  # noqa: E402
from allanite.report import build_report  # noqa: E402
from allanite.report.fmt import clock, g, num, step_params  # noqa: E402
from allanite.report.settings import NOTHING_ADDED  # noqa: E402

FS = 100.0


class _Cells(HTMLParser):
    """Every table: its header rows and body rows as lists of cell texts; and each <table>'s parent tag."""

    def __init__(self):
        super().__init__()
        self.tables: list[dict] = []
        self.stack: list[tuple[str, dict]] = []
        self.cell: list[str] | None = None
        self.section = "thead"

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "table":
            parent = self.stack[-1] if self.stack else ("", {})
            self.tables.append({"head": [], "body": [], "parent": parent})
        elif tag in ("thead", "tbody"):
            self.section = tag
        elif tag == "tr":
            self.tables[-1]["head" if self.section == "thead" else "body"].append([])
        elif tag in ("td", "th"):
            self.cell = []
        self.stack.append((tag, attrs))

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self.cell is not None:
            rows = self.tables[-1]["head" if self.section == "thead" else "body"]
            rows[-1].append("".join(self.cell).strip())
            self.cell = None
        while self.stack and self.stack.pop()[0] != tag:
            pass

    def handle_data(self, data):
        if self.cell is not None:
            self.cell.append(data)


def _tables(html: str) -> list[dict]:
    p = _Cells()
    p.feed(html)
    return p.tables


def _visible_text(html: str) -> str:
    """The page's text without tags, images and the CSS."""
    html = re.sub(r"<style>.*?</style>", "", html, flags=re.S)
    html = re.sub(r'src="data:[^"]*"', "", html)
    return re.sub(r"<[^>]+>", " ", html)


BLANKS = (
    re.compile(r"\bin\s*[;,)]"),  # "q in ;", "channel in ,"
    re.compile(r"=\s*[;,]"),
    re.compile(r"\bat\s*[;,)]"),
    re.compile(r"\[\s*,|,\s*\]"),  # "[, 3]"
    re.compile(r"\bNone\b|\bnan\b"),
    re.compile(r"\de\+0\d( s\b| \[)"),  # "t = 1.1e+03 [987, 1.26e+03]": seconds in exponent form
)


def _blanks(text: str) -> list[str]:
    return [m.group(0) for rx in BLANKS for m in rx.finditer(text)]


# ------------------------------------------------------------------------------------------------
# the pieces


def test_times_along_the_record_are_seconds_to_the_sample():
    assert clock(1199.9412, 100.0) == "1199.94 s"
    assert clock(1200.0, 1.0) == "1200 s"
    assert clock(0.25, 1000.0) == "0.250 s"
    assert clock(8000.456, 100.0, long=True) == "2:13:20.46"
    assert clock(1200.0, 100.0, long=True) == "0:20:00.00"
    assert clock(59.9999, 10.0, long=True) == "0:01:00.0"
    step = {
        "effect": "change_point",
        "statistic": "window_levels",
        "params": {"t": 1100.13},
        "units": {"t": "s"},
        "intervals": {"t": [987.0, 1260.51]},
    }
    assert step_params(step, 100.0, 3000.0, units=True, intervals=True) == "t = 1100.13 s [987.00, 1260.51]"
    assert step_params(step, 100.0, 10_000.0, units=True, intervals=True) == "t = 0:18:20.13 [0:16:27.00, 0:21:00.51]"
    assert step_params(step, 100.0, 3000.0, units=True) == "t = 1100.13 s"


def test_parameters_that_are_strings_lists_or_ints_render():
    step = {
        "effect": "regression",
        "statistic": "allan_curve",
        "params": {"channel": "temperature", "coefficient": 0.0123, "taps": 7, "bands": [1.5, 3, "x"]},
        "units": {"channel": "", "coefficient": "°/s per channel unit", "taps": "samples", "bands": ""},
        "intervals": {"coefficient": [0.011, 0.0136]},
    }
    text = step_params(step, 100.0, 3000.0, units=True, intervals=True)
    assert text == (
        "channel = temperature; coefficient = 0.0123 [0.011, 0.0136] °/s per channel unit; taps = 7 samples; "
        "bands = 1.5, 3, x"
    )
    assert num(1234.6, 3) == "1235" and num(0.5) == "0.5" and num(3.7e-5) == "3.7e-05"
    assert format_param("p", None) == "p = —" and format_param("taps", np.int64(4)) == "taps = 4"


# ------------------------------------------------------------------------------------------------
# a refined report of one axis: a Gauss–Markov bump and a change of noise level at 2000 s


@pytest.fixture(scope="module")
def refined():
    y = allanite.simulate(300_000, FS, N=2e-3, K=2e-5, gauss_markov=[(5e-3, 10.0)], seed=11)
    y[200_000:] *= 2.0
    rep = build_report(y[:, None], FS, unit="deg/s", refine=True, window=30_000, hop=3_000, axis_names=["gyro_x"])
    images = rep.render_figures(progress=False)
    return rep, rep.html(images), images


def test_page_has_no_template_blanks(refined):
    rep, html, _ = refined
    text = _visible_text(html)
    assert _blanks(text) == []
    assert "q (quality factor" in text and "channel (name of the other channel)" in text
    assert "sigma in °/s" in text  # the rate unit named, not "rate unit"
    for table in _tables(html):
        for row in table["head"] + table["body"]:
            assert all(cell != "" for cell in row[1:]), row
    # the summary's parameter units sentence: every parameter with a unit or what it is
    units = rep.summary()["refinement"]["units"]
    assert _blanks(units) == []
    for e in EFFECTS.values():
        for p, _u, _m in e.params:
            assert re.search(rf"\b{p} (in |\()", units), p


def test_change_point_is_printed_in_seconds_to_the_sample(refined):
    rep, html, _ = refined
    ax = rep.summary()["refinement"]["axes"][0]
    cps = [st for st in ax["steps"] if st["effect"] == "change_point"]
    assert len(cps) == 1 and abs(cps[0]["params"]["t"] - 2000.0) < 1.0
    t, (lo, hi) = cps[0]["params"]["t"], cps[0]["intervals"]["t"]
    assert f"t = {t:.2f} s [{lo:.2f}, {hi:.2f}]" in html
    assert f"change_point: t = {t:.2f} s" in rep.text()


def test_refinement_figure_and_davar_overview_are_on_the_page(refined):
    rep, html, images = refined
    assert "refinement_axis0.png" in images and "davar.png" in images
    shown = re.findall(r"<code>([\w.]+\.png)</code></figcaption>", html)
    assert sorted(shown) == sorted(images)
    assert html.index("refinement_axis0.png") > html.index('id="refinement"')


def test_record_table_has_no_header_row_and_tables_scroll(refined):
    rep, html, _ = refined
    tables = _tables(html)
    record = tables[0]
    assert record["head"] == []
    assert record["body"][0] == ["samples per axis", "300000"] and record["body"][1] == ["axes", "1 (gyro_x)"]
    for table in tables:
        assert table["parent"][0] == "div" and table["parent"][1].get("class") == "scroll"
        assert all(any(cell for cell in row) for row in table["head"])  # no empty header row
    assert ".scroll{overflow-x:auto" in html
    assert "300000 samples × 1 axis (gyro_x)" in rep.text()
    assert "× 1 axis at 100 Hz" in repr(rep)


def test_coefficients_over_time_summarise_the_resolved_windows(refined):
    rep, html, _ = refined
    s = rep.series[0]
    ser = rep.summary()["fit"]["series"]["axes"][0]["coefficients"]
    checked = 0
    for t in s.terms:
        v, st = np.asarray(s.values[t]), ser[t]["stats"]
        ok = v > 0
        assert (st["windows_nonzero"], st["windows"]) == (int(ok.sum()), v.size)
        if not ok.any():
            assert st["min"] is None and st["median_resolved"] is None and st["median"] == 0.0
            continue
        scale = np.asarray(s.ieee[t])[ok] / v[ok]
        assert st["min"] == pytest.approx(float(np.min(v[ok] * scale)), rel=1e-12)
        assert st["max"] == pytest.approx(float(np.max(v[ok] * scale)), rel=1e-12)
        assert st["median_resolved"] == pytest.approx(float(np.median(v[ok] * scale)), rel=1e-12)
        # the median is over every window, an unresolved one counted as 0 (not the resolving windows' swings)
        everywhere = np.where(ok, np.asarray(s.ieee[t]), 0.0)
        assert st["median"] == pytest.approx(float(np.median(everywhere)), rel=1e-12)
        assert st["min"] > 0 and s.t[v == np.min(v[ok])][0] == st["t_of_min_s"]
        checked += not ok.all()
    assert checked >= 1  # a term resolved in some windows only (Q and B in this record)
    rows = {
        r[1].split(" —")[0]: r
        for t in _tables(html)
        for r in t["body"]
        if t["head"] and "windows resolved (> 0)" in t["head"][0]
    }
    for t in s.terms:
        st = ser[t]["stats"]
        their = f" (their median {g(st['median_resolved'])})" if 0 < st["windows_nonzero"] < st["windows"] else ""
        assert rows[t][-1] == f"{st['windows_nonzero']}/{st['windows']}{their}"
        assert rows[t][3] == g(st["median"])
        assert not rows[t][4].startswith("0 at")


def test_console_and_page_say_the_same_when_nothing_is_added():
    y = allanite.simulate(120_000, FS, N=2e-3, seed=3)
    rep = build_report(y[:, None], FS, unit="deg/s", refine=True, window=20_000, hop=2_000)
    assert rep.refinements[0] is not None and rep.refinements[0].steps == []
    html = rep.html(rep.render_figures(progress=False))
    assert f'<td class="l">{NOTHING_ADDED}</td>' in html
    assert f"axis 0: {NOTHING_ADDED};" in rep.text()
    assert "nothing found" not in html + rep.text()
    assert json.dumps(rep.summary(), allow_nan=False)


# ------------------------------------------------------------------------------------------------
# the per-axis ADEV figure (issue 32 item 4)


def test_adev_figure_draws_terms_where_they_matter_and_marks_the_unfitted_tau():
    import matplotlib.pyplot as plt

    y = allanite.simulate(200_000, FS, N=2e-3, K=2e-5, Q=1e-4, seed=5)
    r = allanite.avar(y, FS).with_confidence(y)
    f = allanite.fit(r, unit="deg/s", tau_range=(0.1, None))
    assert f.tau[0] > r.tau[0]
    try:
        ax = r.plot(unit="deg/s")
        f.plot(ax=ax, tau=r.tau, points=False, color="k")
        lines = {ln.get_label(): ln for ln in ax.lines}
        model = lines["fitted model"]
        x, v = model.get_xdata(), model.get_ydata()
        assert np.all(np.isnan(v[x < f.tau[0] * (1 - 1e-9)])) and np.all(np.isfinite(v[x >= f.tau[0]]))
        dotted = [ln for ln in ax.lines if ln.get_linestyle() == ":"]
        assert len(dotted) == 1 and np.nanmin(dotted[0].get_xdata()[np.isfinite(dotted[0].get_ydata())]) == r.tau[0]
        labels = [t.get_text() for t in ax.get_legend().get_texts()]
        assert "τ not fitted" in labels
        terms = [ln for name, ln in lines.items() if name[:1] in "QNBKR" and " = " in name]
        assert len(terms) >= 2
        full = np.sqrt(f.curve(x))
        for ln in terms:
            tv = ln.get_ydata()
            drawn = np.isfinite(tv)
            assert drawn.any() and not drawn.all()
            assert np.all(tv[drawn] >= full[drawn] / 10 * (1 - 1e-12))  # within a decade of the model
            assert np.all(ln.get_xdata()[drawn] >= f.tau[0] * (1 - 1e-9))  # not over the τ left out
        # every term over the whole fitted range on request
        ax2 = f.plot(term_decades=None)
        n_line = next(ln for ln in ax2.lines if ln.get_label().startswith("N = "))
        assert np.all(np.isfinite(n_line.get_ydata()))
    finally:
        plt.close("all")
