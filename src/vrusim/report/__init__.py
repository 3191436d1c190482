"""Self-contained HTML reports of a run, the paper reproduction, a Euro NCAP assessment or a sweep.

`build_report(source)` makes a `Report` (sections of escaped HTML plus the results document it shows) and
`write_report(report, path)` renders it into one file with its styles, script, figures and data inline.
See docs/report.md.
"""

from vrusim.report.page import Report, Section, render
from vrusim.report.sources import SourceKind, build_report, check_output, source_kind, write_report

__all__ = ["Report", "Section", "SourceKind", "build_report", "check_output", "render", "source_kind", "write_report"]
