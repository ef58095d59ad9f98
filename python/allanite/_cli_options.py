"""The ``allanite`` command line's words: its help texts, its parser (a usage error is one line) and the
``report`` command's option groups — input, analysis, output — that :func:`allanite.cli.build_parser` puts
together."""

from __future__ import annotations

import argparse

from ._validate import input_word
from .model.effects import EFFECTS
from .units import ACCEL_UNITS

#: ``allanite --help``: what the command line does.
DESCRIPTION = """\
allanite: static and dynamic Allan variance for gyroscopes, IMUs and clocks.

commands:
  report    Allan deviation with intervals, IEEE-952 noise fit and dynamic Allan variance of a
            log, as an HTML page, a JSON summary and PNG figures
  batch     one report per log of a fleet, as Dask tasks, and a fleet summary (fleet.csv,
            fleet.parquet, fleet.html); needs allanite[dask]"""

#: ``allanite --help``, after the options: the exit statuses.
EPILOG = """\
Run 'allanite report --help' for the report's options; 'allanite report' alone analyses the
bundled record (a simulated 3-axis gyro) and writes the report to ./allanite-report/.

exit status:
  0    success
  1    internal error (a bug: please report it with the traceback)
  2    usage or input error (one line on stderr: 'allanite: error: ...')
  130  interrupted"""

#: ``allanite report --help``: what the report holds and the bundled record it runs on by default.
REPORT_DESCRIPTION = """\
Analyse a gyro/IMU/clock log: the overlapping Allan deviation with confidence intervals, the
IEEE-952 noise model (quantization Q, angle random walk N, bias instability B, rate random walk K,
rate ramp R) with intervals and datasheet read-offs, the dynamic Allan variance (DAVAR) and the
noise coefficients over time. Prints a summary and writes, into DIR, one self-contained HTML page
(figures embedded, no network), a JSON file with every number of the page and the figures as PNG.

Without LOG it analyses the bundled record: a deterministic simulated 3-axis gyro, 1 h at 100 Hz
in deg/s, whose angle random walk is 4x larger from 20 to 30 min."""

#: ``allanite report --help``, after the options.
REPORT_EPILOG = """\
examples:
  allanite report                                 # the bundled record -> ./allanite-report/
  allanite report imu.csv.gz --fs 100 --columns gyro_x,gyro_y,gyro_z --unit deg/s
  allanite report gyro.csv --time-column t --unit rad/s --gaps longest --out results/
  allanite report gyro.npy --fs 200 --window 60000 --hop 2000 --taus exp --quiet
  allanite report flight.bag                      # ROS 1 bag: sensor_msgs/Imu, rad/s
  allanite report imu0.csv                        # EuRoC: the accelerometer in DIR/accelerometer/
  allanite report imu.npy --fs 500 --frames 20 --forecast 60:30   # paper 004: GM(1,1) forecasts
  allanite report acc.npy --fs 100 --refine-candidates bandwidth,drift   # refine trying 2 effects
  allanite report log.csv --fs 10 --columns g_x,g_y --unit deg/s --channels temp
                                                  # refine (implied), regressing on the temp column
  allanite report log.csv --fs 10 --unit deg/s --refine   # a 'temp' column: a channel, not an axis

files written to DIR:
  report.html              the report, one self-contained page
  summary.json             every number of the page, with units (schema allanite-report/1)
  adev.png                 all axes: Allan deviation with confidence bands and fits
  davar.png                all axes: DAVAR heat maps (time x tau, log colour), one panel per axis
  coefficients.png         all axes: noise coefficients per DAVAR window with intervals
  adev_axisK.png           axis K: ADEV with confidence band, fitted model and each term
  davar3d_axisK.png        axis K: DAVAR surface (t, log10 tau, log10 ADEV)
  refinement_axisK.png     axis K (--refine): starting and refined model, residuals before/after
  frames_axisK.png         axis K (--frames/--forecast): coefficients per frame with intervals
  forecast_axisK.png       axis K (--frames/--forecast): forecasts of the resolved coefficients
  accelerometer/           a log's accelerometer columns, where their names give its unit beside a
                           gyro's: the same files, VRW in m/s/sqrt(h), bias instability in ug

A progress bar goes to stderr when it is a terminal; when stdout is not one (a pipe, a log file),
each step is also printed there as it starts. --quiet prints nothing but errors.

exit status:
  0    success
  1    internal error (a bug: please report it with the traceback)
  2    usage or input error (one line on stderr: 'allanite: error: ...')
  130  interrupted"""


class UsageError(Exception):
    """A bad command line: reported as one line, exit status 2."""


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are a :class:`UsageError` (one line) instead of argparse's usage block."""

    def error(self, message):  # one line instead of argparse's usage block
        raise UsageError(f"{message} (see '{self.prog} --help')")


def formatter(prog):
    """The help layout: the texts as written, options in a column at 30, lines of 100."""
    return argparse.RawDescriptionHelpFormatter(prog, max_help_position=30, width=100)


def add_input_options(rep: argparse.ArgumentParser) -> None:
    """The options that describe a LOG file: rate, columns, time, unit, gaps, the accelerometer's."""
    inp = rep.add_argument_group("input (LOG only)")
    inp.add_argument(
        "--fs", type=float, metavar="HZ", help="sampling rate in Hz (or give --time-column; ROS bags use their stamps)"
    )
    inp.add_argument(
        "--columns",
        metavar="C1,C2,...",
        help="columns that are the samples, by name or 0-based index, comma-separated; one per "
        "axis (default: every column but the time column — or, when the header also names "
        "accelerometer columns (acc_x, ...), the ones it names as gyro (gyro_x, ...); when the names give a gyro's "
        "and an accelerometer's units (w_RS_S_x [rad s^-1], a_RS_S_x [m s^-2]), each in its own report: the "
        "accelerometer's in DIR/accelerometer/)",
    )
    inp.add_argument("--time-column", metavar="C", help="column of sample times: derives --fs, finds gaps")
    inp.add_argument(
        "--time-unit",
        choices=("s", "ms", "us", "ns"),
        help="unit of the time column (default: the unit its name ends in — time_ns, t [ms] — else s); with --fs "
        "only beside --time-column (else an error: no time column is read)",
    )
    inp.add_argument(
        "--unit",
        metavar="U",
        help="unit of the samples: deg/s, rad/s, deg/h, mrad/s, urad/s, ... (rate input) or deg, rad, "
        "arcsec, ... (increment/angle input), or an accelerometer's m/s^2, g, mg, ... (rate input: the report is "
        "an accelerometer's, its coefficients in m/s/√h, µg, m/s/h^1.5); without it the report says the unit is "
        "unknown and gives the noise coefficients in base form",
    )
    inp.add_argument(
        "--input",
        type=input_word,
        choices=("rate", "increment", "angle"),
        help="what the samples are: rate (default), angle increments per sample, cumulative angle (allantools' and "
        "Stable32's phase is angle, their freq/frequency rate)",
    )
    inp.add_argument(
        "--gaps",
        choices=("error", "longest", "split", "nan"),
        help="when the time column shows gaps: stop with the list of gaps (default), analyse the "
        "longest gap-free stretch, or the same and list every stretch (split), or keep the whole log with the "
        "missing rows marked NaN (nan): the Allan curves skip the terms that touch one, the refinement fills "
        "them (at most 5 %% missing)",
    )
    inp.add_argument(
        "--channels",
        metavar="C1,C2,...",
        help="other columns of the same log (a temperature, a supply voltage, an accelerometer), by name or "
        "0-based index, read at the same rate and cut at the same gaps as the samples: every axis's model "
        "refinement regresses the rate on them (implies --refine; with --refine-candidates, regression must be "
        "among them; a channel is not also an axis). Their unit is unknown: a coefficient is per unit of the "
        "channel (deg/s per unit of temp). Default: the columns whose names say temperature (temp, temperature, "
        "imu_temp, TEMP_OUT, 'T [degC]', ...: a word temp/temperature or a temperature unit in brackets, any "
        "case) — never an axis, and a channel when the report refines (--refine; they do not imply it); "
        "'none': no channel. A channel's missing values (nan or empty) are interpolated linearly, with a warning",
    )
    inp.add_argument(
        "--accel-columns",
        metavar="C1,C2,...",
        help="accelerometer columns of the same log, for --kalibr (fitted like the gyro, written as "
        "accelerometer_noise_density and accelerometer_random_walk; default: the accelerometer report's fits, "
        "where one is written in DIR/accelerometer/)",
    )
    inp.add_argument(
        "--accel-unit",
        choices=ACCEL_UNITS,
        help="unit of the accelerometer columns (default: the one their names give, [g] or [m s^-2], else m/s^2; "
        "g = 9.80665 m/s^2); with --unit and without --columns, the columns named as an accelerometer's (acc_x, "
        "...) are also reported in it, in DIR/accelerometer/; without --unit, a log whose analysed columns are all "
        "named as an accelerometer's (ax, acc_x, ...) is reported in it",
    )


def add_analysis_options(rep: argparse.ArgumentParser) -> None:
    """The options of the analysis: tau grid, DAVAR windows, estimator, refine, fit, memory, frames, sections."""
    ana = rep.add_argument_group("analysis")
    ana.add_argument(
        "--taus",
        metavar="GRID",
        default="octave",
        help="tau of the static analysis: octave (default), decade, exp, all, or seconds "
        "comma-separated (0.01,0.1,1,10)",
    )
    ana.add_argument("--window", type=int, metavar="N", help="DAVAR window in samples (default: 1/12 of the record)")
    ana.add_argument(
        "--hop", type=int, metavar="N", help="DAVAR hop between windows in samples (default: 1/25 of the window)"
    )
    ana.add_argument(
        "--estimator",
        choices=("oavar", "theoh"),
        default="oavar",
        help="oavar: overlapping Allan deviation and DAVAR (default); theoh: TheoH for the record and "
        "paper 001's dynamic TheoH (DHVAR) over time, reaching 75%% of the record or window "
        "(default window then at most 2001 samples)",
    )
    _add_refine_options(ana)
    ana.add_argument("--no-fit", action="store_true", help="skip the noise-model fit (whole record and per window)")
    ana.add_argument(
        "--max-memory",
        type=float,
        metavar="BYTES",
        help="memory budget of the report (default: ALLANITE_MAX_MEMORY or 2 GiB); a request over it is "
        "refused at once with a --hop that fits",
    )
    ana.add_argument(
        "--frames",
        type=float,
        metavar="SEC",
        help="time-frame DAVAR (paper 004): fit the noise model in consecutive frames of SEC seconds and add a "
        "coefficient-forecast section (GM(1,1), improved GM(1,1) and baselines)",
    )
    ana.add_argument(
        "--forecast",
        metavar="BUILD:CHECK",
        help="frames that build / check the forecast (e.g. 60:30; default 2/3 : 1/3 of the frames); without "
        "--frames the record is cut into BUILD+CHECK frames",
    )
    ana.add_argument(
        "--taper",
        choices=("hann", "hann_signal"),
        help="add a section: the DAVAR with this taper beside the rectangular one, coefficients per window (paper 002)",
    )
    ana.add_argument(
        "--split",
        metavar="WAVELET",
        help="add a section: wavelet split (e.g. db5, 5 levels) and the window-function combination "
        "(low band rect, high band Hann), coefficients per window (paper 002)",
    )


def _add_refine_options(ana) -> None:
    """The refinement's options in the analysis group: --refine, its candidates and the sensor's own filter."""
    ana.add_argument(
        "--refine",
        action="store_true",
        help="also look for what the noise model lacks ("
        + ", ".join(e.label for e in EFFECTS.values() if e.domain != "channels")
        + ") and add a model-refinement section, with what the final model still misses (or that it passes "
        "every calibrated check); a few seconds per axis and million samples",
    )
    ana.add_argument(
        "--refine-candidates",
        metavar="NAMES",
        help="refine (as --refine) trying only these effects, comma-separated ("
        + ", ".join(e.name for e in EFFECTS.values() if e.domain != "channels")
        + "; regression as well where a channel is given; e.g. without outliers on quantised accelerometers); "
        "'none': only say what the five-term model still misses",
    )
    ana.add_argument(
        "--refine-filter",
        metavar="FILE",
        help="the sensor's own digital filter, for the refinement (implies --refine): a text file of one row of FIR "
        "taps, or two rows (IIR b, then a), numbers split by commas or spaces; the bandwidth effect's kind is then "
        "this filter, exact, its shape fixed, and the page says so",
    )
    ana.add_argument(
        "--refine-filter-rate",
        type=float,
        metavar="HZ",
        help="the rate --refine-filter runs at, when faster than the output rate (a decimating filter: a whole "
        "multiple of it); default the output rate",
    )


def add_output_options(rep: argparse.ArgumentParser) -> None:
    """The options of what is written: the folder, Kalibr's imu.yaml, quiet."""
    out = rep.add_argument_group("output")
    out.add_argument(
        "--out",
        default="allanite-report",
        metavar="DIR",
        help="folder for the report, created if needed (default: %(default)s)",
    )
    out.add_argument(
        "--kalibr",
        metavar="YAML",
        help="also write a Kalibr / ROS imu.yaml (noise densities and random walks in SI, the worst axis; "
        "needs --unit for a LOG)",
    )
    out.add_argument(
        "--kalibr-aggregate",
        choices=("worst", "mean"),
        default="worst",
        help="one value from the axes: the largest (default, as allan_variance_ros) or the mean (as imu_utils)",
    )
    out.add_argument("-q", "--quiet", action="store_true", help="print nothing but errors")
