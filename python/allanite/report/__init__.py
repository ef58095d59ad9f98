"""The allanite report: numbers (``summary.json``), terminal text, figures and one HTML page.

:func:`build_report` (or :func:`from_log` for a :class:`~allanite.Log`) computes everything and
returns a :class:`Report`; :meth:`Report.write` writes the folder. The page is rendered from the
Jinja2 template ``template.html.j2`` with ``report.css`` beside it.
"""

from .build import Report, build_report, from_log, log_source
from .settings import FIT_MODEL, default_hop, default_window

__all__ = ["Report", "build_report", "from_log", "log_source", "default_window", "default_hop", "FIT_MODEL"]
