"""The report's HTML page."""

from __future__ import annotations

import base64
import html as _html
import math

from .._core import __version__
from .fmt import duration, g
from .settings import REPORT_ESTIMATORS

__all__ = ["html_page"]


# --------------------------------------------------------------------------------------------------
# HTML

_CSS = """
body{font-family:system-ui,-apple-system,"Segoe UI",Roboto,Helvetica,Arial,sans-serif;margin:0 auto;
max-width:1100px;padding:1em 1.5em;color:#1b1b1b;line-height:1.45}
h1{font-size:1.6em;margin-bottom:.1em}h2{border-bottom:2px solid #ddd;padding-bottom:.2em;margin-top:1.6em}
h3{margin-bottom:.3em}.sub{color:#555;margin-top:0}nav a{margin-right:1em}
table{border-collapse:collapse;margin:.6em 0;font-size:.9em}
th,td{border:1px solid #ddd;padding:.25em .6em;text-align:right;font-variant-numeric:tabular-nums}
th{background:#f3f3f3}td.l,th.l{text-align:left}
figure{margin:.8em 0;display:inline-block;vertical-align:top;max-width:100%}
figure img{max-width:100%;height:auto;border:1px solid #eee}
figcaption{font-size:.85em;color:#555;max-width:720px}
.note{background:#fff7e0;border-left:4px solid #e0a800;padding:.4em .8em;margin:.4em 0}
.pair figure{max-width:49%}code{background:#f3f3f3;padding:0 .2em}
footer{margin-top:2em;color:#777;font-size:.85em}
"""


def _e(s) -> str:
    return _html.escape(str(s), quote=True)


def _table(header, rows, left=1) -> str:
    h = "".join(f'<th class="l">{_e(c)}</th>' if i < left else f"<th>{_e(c)}</th>" for i, c in enumerate(header))
    body = []
    for r in rows:
        body.append(
            "<tr>"
            + "".join(f'<td class="l">{_e(c)}</td>' if i < left else f"<td>{_e(c)}</td>" for i, c in enumerate(r))
            + "</tr>"
        )
    return f"<table><thead><tr>{h}</tr></thead><tbody>{''.join(body)}</tbody></table>"


def _img(images, specs_by_name, name) -> str:
    if name not in images:
        return ""
    _, title, caption, _, _ = specs_by_name[name]
    data = base64.b64encode(images[name]).decode("ascii")
    return (
        f'<figure><img src="data:image/png;base64,{data}" alt="{_e(title)}">'
        f"<figcaption>{_e(caption)} <code>{_e(name)}</code></figcaption></figure>"
    )


def html_page(rep, images: dict) -> str:
    """The self-contained HTML page of a report, figures embedded as data URIs."""
    s = rep.summary()
    specs = {sp[0]: sp for sp in rep.figure_specs()}
    rec, st, dy, fit = s["record"], s["static"], s["dynamic"], s["fit"]
    names = rec["axis_names"]
    au = rec["adev_unit"] or "samples' unit"
    out = []
    out.append(
        f"<header><h1>Allan variance report — {_e(rec['name'])}</h1>"
        f'<p class="sub">allanite {_e(__version__)} · {_e(s["created"])}</p></header>'
    )
    out.append(
        '<nav><a href="#record">Record</a><a href="#static">Allan deviation</a>'
        '<a href="#model">Noise model</a><a href="#davar">Dynamic Allan variance</a>'
        '<a href="#series">Coefficients over time</a></nav>'
    )

    # record
    src = rec["source"]
    rows = [
        ("samples per axis", rec["samples"]),
        ("axes", f"{rec['axes']} ({', '.join(names)})"),
        ("sampling rate", f"{rec['fs_hz']:g} Hz"),
        ("duration", f"{g(rec['duration_s'], 6)} s ({duration(rec['duration_s'])})"),
        ("unit", rec["unit"] or "unknown"),
        ("input", rec["input"]),
    ]
    for key, label in (
        ("path", "file"),
        ("format", "format"),
        ("what", "description"),
        ("fs_from", "fs from"),
        ("samples_in_file", "samples in file"),
        ("seed", "seed"),
    ):
        if src.get(key) is not None:
            rows.append((label, src[key]))
    if src.get("gaps"):
        rows.append(
            (
                "gaps",
                "; ".join(f"{g['duration_s']:.6g} s after sample {g['after_sample']}" for g in src["gaps"][:10])
                + (" …" if len(src["gaps"]) > 10 else ""),
            )
        )
    out.append('<section id="record"><h2>Record</h2>' + _table(("", ""), rows, left=1))
    for note in s["notes"]:
        out.append(f'<p class="note">{_e(note)}</p>')
    out.append("</section>")

    # static
    conf = st["confidence"]
    theoh = st["source"] is not None
    titles = REPORT_ESTIMATORS["theoh" if theoh else "oavar"][3:]
    edf_words = (
        "Greenhall's equivalent degrees of freedom (ν) at Allan τ and Howe's Theo1 ν at TheoBR τ "
        f"(bias ratio kf = {', '.join(g(k) for k in st['kf'])}; TheoBR values belong to τ = 0.75·m/fs"
        + (
            f"; TheoBR and kf from block averages of {st['theo_decimation']} samples — Taylor & Howe's "
            "fast TheoBR — as Theo1 of the full record would cost O(N²)"
            if (st.get("theo_decimation") or 1) > 1
            else ""
        )
        + ")"
        if theoh
        else "Greenhall's equivalent degrees of freedom (ν)"
    )
    out.append(
        f'<section id="static"><h2>{_e(titles[0])}</h2>'
        f"<p>Estimator <code>{_e(st['estimator'])}</code> on the <code>{_e(st['grid'])}</code> τ grid; "
        f"{conf:.1%} χ² intervals with {edf_words} for the noise type "
        f"identified at each τ. ADEV in {_e(au)}.</p>"
    )
    out.append(_img(images, specs, "adev.png"))
    header = ["τ (s)", "n"] + [h for nm in names for h in (f"{nm} ADEV", "interval", "ν")]
    rows = []
    for i, tau in enumerate(st["tau_s"]):
        r = [g(tau), st["n"][i]]
        for k in range(len(names)):
            lo, hi = st["adev_ci_low"][k][i], st["adev_ci_high"][k][i]
            r += [g(st["adev"][k][i]), f"[{g(lo)}, {g(hi)}]", g(st["edf"][k][i], 3)]
        rows.append(r)
    out.append(_table(header, rows, left=0) + "</section>")

    # model
    out.append('<section id="model"><h2>Noise model (IEEE Std 952)</h2>')
    if fit["axes"] is not None:
        ieee = fit["unit_known"]
        out.append(
            f"<p>Weighted non-negative least squares in variance space, iteratively reweighted, on "
            f"octave-spaced τ: <code>{_e(fit['model'])}</code>. {fit['confidence']:.1%} intervals. "
            + (
                "Coefficients in IEEE-952 units; base form in the second table."
                if ieee
                else "The unit is unknown, so coefficients are in base form (the samples' unit and seconds)."
            )
            + "</p>"
        )
        if ieee:
            header = ["term", "unit"] + names
            rows = []
            for t in fit["terms"]:
                c0 = fit["axes"][0]["coefficients"][t]
                rows.append(
                    [f"{t} — {c0['name']}", c0["ieee_unit"]]
                    + [
                        f"{g(c['ieee'])} [{g(c['ieee_ci'][0])}, {g(c['ieee_ci'][1] if c['ieee_ci'][1] is not None else math.inf)}]"
                        for c in (ax["coefficients"][t] for ax in fit["axes"])
                    ]
                )
                if "also" in c0:
                    rows.append(
                        [f"{t} — {c0['name']}", c0["also"]["unit"]]
                        + [
                            f"{g(c['also']['value'])} [{g(c['also']['ci'][0])}, "
                            f"{g(c['also']['ci'][1] if c['also']['ci'][1] is not None else math.inf)}]"
                            for c in (ax["coefficients"][t] for ax in fit["axes"])
                        ]
                    )
            out.append(_table(header, rows, left=2))
        header = ["term", "base unit"] + names
        rows = []
        for t in fit["terms"]:
            c0 = fit["axes"][0]["coefficients"][t]
            rows.append(
                [f"{t} — {c0['name']}", c0["unit"] or "(samples' unit)·s^p"]
                + [
                    f"{g(c['value'])} [{g(c['ci'][0])}, {g(c['ci'][1] if c['ci'][1] is not None else math.inf)}]"
                    for c in (ax["coefficients"][t] for ax in fit["axes"])
                ]
            )
        out.append(_table(header, rows, left=2))
        rows = [
            ["χ²/dof"] + [g(ax["chi2_dof"], 4) for ax in fit["axes"]],
            ["χ², dof"] + [f"{g(ax['chi2'], 4)}, {ax['dof']}" for ax in fit["axes"]],
            ["p-value"] + [g(ax["p_value"], 3) for ax in fit["axes"]],
            ["τ points fitted"]
            + [f"{len(ax['tau_s'])} ({g(ax['tau_s'][0])}–{g(ax['tau_s'][-1])} s)" for ax in fit["axes"]],
        ]
        ro = [ax["readoffs"] for ax in fit["axes"]]
        rows.append(
            [f"σ(1 s) ({au})"]
            + [g(r["adev_at_1s"]) + (" (interpolated)" if r["adev_at_1s_interpolated"] else "") for r in ro]
        )
        rows.append([f"σ minimum ({au}) at τ (s)"] + [f"{g(r['adev_min'])} at {g(r['tau_at_min_s'])}" for r in ro])
        rows.append([f"σmin/0.664 ({au})"] + [g(r["bias_instability_readoff"]) for r in ro])
        if ieee:
            rows.append(
                [f"read-off N = σ(1 s)·√1 s ({ro[0]['arw_readoff_ieee_unit']})"]
                + [g(r["arw_readoff_ieee"]) for r in ro]
            )
            rows.append(
                [f"read-off B = σmin/0.664 ({ro[0]['bias_instability_readoff_ieee_unit']})"]
                + [g(r["bias_instability_readoff_ieee"]) for r in ro]
            )
        out.append("<h3>Goodness of fit and datasheet read-offs</h3>" + _table([""] + names, rows, left=1))
    elif not fit["requested"]:
        out.append("<p>Not fitted (<code>--no-fit</code>).</p>")
    else:
        out.append(f'<p class="note">Not fitted: {_e(fit["error"])}</p>')
    out.append("<div>" + "".join(_img(images, specs, f"adev_axis{k}.png") for k in range(len(names))) + "</div>")
    out.append("</section>")

    # davar
    what = (
        "the static TheoH of its window (its own bias ratio kf and switch point)"
        if theoh
        else "the static overlapping Allan variance of its window"
    )
    grid_words = "octave grid" if dy["grid"] == "octave" else "exponential grid"
    out.append(
        f'<section id="davar"><h2>{_e(titles[1])}</h2><p>Window {dy["window_samples"]} samples '
        f"({g(dy['window_s'])} s, {_e(dy['window_rule'])}), hop {dy['hop_samples']} samples "
        f"({g(dy['hop_s'])} s, {_e(dy['hop_rule'])}): {dy['windows']} windows × {len(dy['tau_s'])} τ "
        f"({g(dy['tau_s'][0])}–{g(dy['tau_s'][-1])} s, {grid_words}), method "
        f"<code>{_e(dy['method'])}</code>. Each column is exactly {what}.</p>"
    )
    rows = [
        [
            ax["name"],
            g(ax["tau_s"]),
            g(ax["adev_shortest_tau_median"]),
            f"{g(ax['adev_shortest_tau_max'])} at {ax['t_of_max_s']:.0f} s",
            f"{g(ax['adev_shortest_tau_min'])} at {ax['t_of_min_s']:.0f} s",
            g(ax["max_over_min"], 3),
        ]
        for ax in dy["axes"]
    ]
    out.append(_table(["axis", "τ (s)", f"median ADEV ({au})", "max at t", "min at t", "max/min"], rows, left=1))
    for k, nm in enumerate(names):
        out.append(
            f'<h3>{_e(nm)}</h3><div class="pair">'
            + _img(images, specs, f"davar_axis{k}.png")
            + _img(images, specs, f"davar3d_axis{k}.png")
            + "</div>"
        )
    out.append("</section>")

    # series
    out.append('<section id="series"><h2>Noise coefficients over time</h2>')
    ser = fit.get("series")
    if ser and ser["axes"] is not None:
        out.append(
            f"<p>The noise model fitted in every DAVAR window ({ser['confidence']:.1%} intervals) — paper "
            f"002's 2-D representation. Median, minimum and maximum over the windows"
            f"{', in IEEE-952 units' if fit['unit_known'] else ' (base form)'}:</p>"
        )
        rows = []
        for ax in ser["axes"]:
            for t, c in ax["coefficients"].items():
                sc = c["stats"]
                rows.append(
                    [
                        ax["name"],
                        f"{t} — {c['name']}",
                        sc["unit"] or "",
                        g(sc["median"]),
                        f"{g(sc['min'])} at {g(sc['t_of_min_s'])} s",
                        f"{g(sc['max'])} at {g(sc['t_of_max_s'])} s",
                        f"{sc['windows_nonzero']}/{len(ax['t_s'])}",
                    ]
                )
        out.append(_table(["axis", "term", "unit", "median", "min", "max", "windows > 0"], rows, left=3))
        out.append(
            "<div>" + "".join(_img(images, specs, f"coefficients_axis{k}.png") for k in range(len(names))) + "</div>"
        )
    elif not fit["requested"]:
        out.append("<p>Not fitted (<code>--no-fit</code>).</p>")
    else:
        out.append(f'<p class="note">Not fitted: {_e((ser or {}).get("error"))}</p>')
    out.append("</section>")
    ref = s.get("refinement")
    if ref is not None:
        out.append(
            '<section id="refinement"><h2>Model refinement</h2><p>What the five-term model lacks: '
            "<code>allanite.refine</code> traced the residual to Gauss–Markov or sinusoid signatures in the "
            "Allan curve, or to changes of level along the record (16 windows), and kept an effect only where it "
            "earned its parameters (BIC on an effective χ²). Parameters: σ and amplitude in the rate unit, "
            "T<sub>c</sub> and t in s, f0 in Hz; intervals ~68 %. Its χ²/dof weights each τ of a dense curve "
            "independently, so it is not the fit table's χ²/dof (which accounts for the correlation between "
            "τ).</p>"
        )
        rows = []
        for ax in ref["axes"]:
            if ax.get("error"):
                rows.append([ax["name"], "failed", "", "", ""])
                continue
            if not ax["steps"]:
                rows.append([ax["name"], "nothing found", "", f"{g(ax['start']['chi2_dof'], 3)}", ""])
            for st in ax["steps"]:
                params = "; ".join(
                    f"{p} = {g(v, 3)} [{g(st['intervals'][p][0], 3)}, {g(st['intervals'][p][1], 3)}]"
                    for p, v in st["params"].items()
                )
                rows.append(
                    [
                        ax["name"],
                        st["effect"],
                        params,
                        f"{g(st['before']['chi2_dof'], 3)} → {g(st['after']['chi2_dof'], 3)}",
                        f"{g(st['before']['rms_adev_pct'], 3)} → {g(st['after']['rms_adev_pct'], 3)} %",
                    ]
                )
        out.append(
            _table(
                ["axis", "effect", "parameters", "χ²/dof before → after", "RMS ADEV error before → after"], rows, left=3
            )
        )
        out.append("</section>")
    out.append(
        f"<footer>Every number on this page is in <code>summary.json</code> beside it, with its unit. "
        f"Figures: {', '.join(_e(n) for n in images)}.</footer>"
    )
    body = "\n".join(out)
    return (
        f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
        f'<meta name="viewport" content="width=device-width, initial-scale=1">'
        f"<title>allanite report — {_e(rec['name'])}</title><style>{_CSS}</style></head>\n<body>\n{body}\n"
        f"</body></html>\n"
    )
