"""`vrusim summarize`: collision probability and metric statistics of a sweep's results, overall and per group."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer
from rich import box
from rich.console import Console
from rich.table import Table

from vrusim.cli.fit import fit_table, natural_width
from vrusim.cli.options import JsonOption, split_names
from vrusim.cli.output import console, escape, print_json, user_errors

_STAT_TITLES = {"count": "n", "mean": "mean", "std": "std", "min": "min", "p5": "p5", "median": "median",
                "p95": "p95", "max": "max"}  # fmt: skip


_HEADER_LINE = 12
"""A parameter name longer than this is broken at its dots in a column header."""


def _num(value: float | None, digits: int = 4) -> str:
    """`value` to `digits` significant digits; "–" when absent."""
    return "–" if value is None else f"{value:.{digits}g}"


def _key_text(value: Any) -> str:
    """A group's value of one column: the bin as low–high (and centre), or the value."""
    if value is None:
        return "null"
    if isinstance(value, dict):
        return f"{value['low']:.4g} – {value['high']:.4g} (≈{value['centre']:.4g})"  # spaces: it may wrap
    return f"{value:.6g}" if isinstance(value, float) else str(value)


def _header_lines(name: str) -> str:
    """`name` on lines of at most about `_HEADER_LINE` characters: broken after its dots, and a segment that is
    still longer after its underscores (`v2x.` / `channel.` / `latency_s`; `heading_` / `gain_per_m`)."""
    if len(name) <= _HEADER_LINE:
        return name
    lines = []
    for segment in name.replace(".", ".\n").split("\n"):
        if len(segment) <= _HEADER_LINE:
            lines.append(segment)
            continue
        line = ""
        for part in segment.replace("_", "_\n").split("\n"):
            if line and len(line) + len(part) > _HEADER_LINE:
                lines.append(line)
                line = ""
            line += part
        lines.append(line)
    return "\n".join(lines)


def _by_header(described: dict[str, Any]) -> str:
    """A grouping parameter's column header; a long dotted path on several lines (`_header_lines`), so that two
    of them still leave room for the numbers at 80 columns."""
    header = escape(_header_lines(described["name"]))
    return f"{header}\n{len(described['edges']) - 1} bins" if described["binned"] else header


def _add_key_columns(table: Table, by: list[dict[str, Any]]) -> None:
    """The grouping columns: one per parameter; with two or more, one column listing them numbered (1:, 2:, ...),
    which leaves room for the numbers at 80 columns whatever the parameter names."""
    if len(by) < 2:
        for described in by:
            table.add_column(_by_header(described))
        return
    names = []
    for index, described in enumerate(by, start=1):
        lines = _header_lines(described["name"]).split("\n")
        if described["binned"]:
            lines.append(f"({len(described['edges']) - 1} bins)")
        names.append(escape(f"{index}: " + "\n".join(lines)))
    table.add_column("\n".join(names))


def _key_cells(key: dict[str, Any], by: list[dict[str, Any]]) -> list[str]:
    """A group's cells in the grouping columns (`_add_key_columns`)."""
    texts = [escape(_key_text(key[d["name"]])) for d in by]
    return texts if len(by) < 2 else ["\n".join(f"{i}: {text}" for i, text in enumerate(texts, start=1))]


def outcome_table(summary: dict[str, Any], terminal: Console | None = None) -> Table:
    """Runs, collisions, P(collision) and its Wilson 95 % interval, stalled / incomplete runs: one row per group
    (or overall). Too wide for `terminal` even when fitted, it leaves out the stalled / incomplete column (and
    says so)."""
    table = _outcome_table(summary, stalls=True)
    if terminal is not None and natural_width(fit_table(table, terminal), terminal) > terminal.width:
        table = _outcome_table(summary, stalls=False)
        table.caption = "stalled / incomplete runs: widen the terminal, or --json"
        table.caption_justify = "left"
    return table


def _outcome_table(summary: dict[str, Any], stalls: bool) -> Table:
    table = Table(title="Collisions (Wilson 95 % interval)", box=box.SIMPLE_HEAD, title_justify="left")
    _add_key_columns(table, summary["by"])
    titles = ("Runs", "Collisions", "P(collision)", "95 % interval", *(("Stalled /\nincomplete",) if stalls else ()))
    for name in titles:
        table.add_column(name, justify="right", no_wrap=True)
    rows = summary["groups"] if summary["by"] else [summary["overall"]]
    for row in rows:
        low, high = row["collision_probability_95"]
        style = "red" if row["collisions"] else "green"
        stalled = "–" if row.get("stalled") is None else f"{row['stalled']} / {row['incomplete']}"
        table.add_row(
            *_key_cells(row.get("key", {}), summary["by"]),
            str(row["runs"]),
            f"[{style}]{row['collisions']}[/]",
            _num(row["collision_probability"]),
            f"{low:.3f}–{high:.3f}",
            *((stalled,) if stalls else ()),
        )
    return table


_DROPPED_WHEN_NARROW = ("p5", "p95")
"""Statistics a grouped metric table leaves out when the terminal is too narrow for all of them (in --json)."""


def _grouped_table(summary: dict[str, Any], metric: str, stats_names: list[str]) -> Table:
    table = Table(title=escape(metric), box=box.SIMPLE_HEAD, title_justify="left")
    _add_key_columns(table, summary["by"])
    for name in stats_names:
        table.add_column(_STAT_TITLES[name], justify="right", no_wrap=True)
    for group in summary["groups"]:
        stats = group["metrics"][metric]
        table.add_row(
            *_key_cells(group["key"], summary["by"]),
            *(str(stats[s]) if s == "count" else _num(stats[s]) for s in stats_names),
        )
    return table


def metric_tables(summary: dict[str, Any], terminal: Console | None = None) -> list[Table]:
    """Without groups one table, a row per metric; with groups one table per metric, a row per group. A grouped
    table too wide for `terminal` even when fitted leaves out p5 and p95 (and says so)."""
    if not summary["metrics"]:
        return []
    if not summary["by"]:
        table = Table(title="Metrics (all runs)", box=box.SIMPLE_HEAD, title_justify="left")
        table.add_column("Metric", no_wrap=True)
        for title in _STAT_TITLES.values():
            table.add_column(title, justify="right", no_wrap=True)
        for metric in summary["metrics"]:
            stats = summary["overall"]["metrics"][metric]
            table.add_row(escape(metric), str(stats["count"]), *(_num(stats[s]) for s in list(_STAT_TITLES)[1:]))
        return [table]
    tables = []
    for metric in summary["metrics"]:
        table = _grouped_table(summary, metric, list(_STAT_TITLES))
        if terminal is not None and natural_width(fit_table(table, terminal), terminal) > terminal.width:
            narrow = [name for name in _STAT_TITLES if name not in _DROPPED_WHEN_NARROW]
            table = _grouped_table(summary, metric, narrow)
            table.caption = "p5 and p95: widen the terminal, or --json"
            table.caption_justify = "left"
        tables.append(table)
    return tables


def _plot(results, plot: Path, x: str, y: str | None, metric: str | None, bins: int) -> Path:
    """Check the plot options against the results, summarise by x (and y) and write the figure."""
    from vrusim.errors import UserInputError
    from vrusim.sweep.summarize import summarize
    from vrusim.viz.sensitivity import write_sensitivity_plot

    results.check_group(x, "--x")
    if y is not None:
        results.check_group(y, "--y")
        if y == x:
            raise UserInputError(f"--y: must name a parameter other than --x ({x!r})")
    metrics = [results.check_metric(metric, "--metric")] if metric is not None else []
    summary = summarize(results, by=[x] if y is None else [x, y], bins=bins, metrics=metrics)
    try:
        write_sensitivity_plot(summary, plot, x, y, metric)
    except UserInputError as error:
        message = str(error)
        raise UserInputError(message if message.startswith("--plot") else f"--plot: {message}") from None
    return plot


def summarize_command(
    results: Annotated[
        Path, typer.Argument(metavar="RESULTS", help="Sweep results directory (vrusim sweep).", show_default=False)
    ],
    by: Annotated[
        str | None, typer.Option("--by", help="Comma-separated parameters to group by (dotted paths).")
    ] = None,
    bins: Annotated[
        int, typer.Option("--bins", help="Equal-width bins for a parameter with more distinct values than this.")
    ] = 10,
    metrics: Annotated[
        str | None,
        typer.Option(
            "--metrics", help="Comma-separated metrics (default: min_ttc_s, impact_ego_speed_mps and the scores)."
        ),
    ] = None,
    as_json: JsonOption = False,
    plot: Annotated[
        Path | None,
        typer.Option("--plot", metavar="OUT.png|OUT.svg|OUT.pdf", help="Write a sensitivity figure (needs --x)."),
    ] = None,
    x: Annotated[str | None, typer.Option("--x", help="Plot: parameter on the x axis.")] = None,
    y: Annotated[str | None, typer.Option("--y", help="Plot: second parameter (heat map).")] = None,
    metric: Annotated[
        str | None, typer.Option("--metric", help="Plot: this metric's mean instead of P(collision).")
    ] = None,
) -> None:
    """Collision probability (Wilson 95 %) and metric statistics of a sweep, overall or per parameter group."""
    with user_errors():
        from vrusim.errors import UserInputError
        from vrusim.sweep.summarize import open_results, summarize
        from vrusim.viz.sensitivity import check_plot_path

        if plot is None:
            for option, value in (("--x", x), ("--y", y), ("--metric", metric)):
                if value is not None:
                    raise UserInputError(f"{option}: only used with --plot OUT.png|OUT.svg|OUT.pdf")
        else:
            from vrusim.io.paths import check_output_file

            check_plot_path(check_output_file(plot, "--plot"))
            if x is None:
                raise UserInputError("--plot: needs --x PARAMETER (and --y PARAMETER for a heat map)")
        chosen = split_names(metrics, "--metrics") if metrics is not None else None
        opened = open_results(results)
        summary = summarize(opened, by=split_names(by, "--by"), bins=bins, metrics=chosen)
        if plot is not None:
            _plot(opened, plot, x, y, metric, bins)
    if as_json:
        print_json(summary)
        return
    out = console()
    title = summary["name"] or results.name
    colour = "yellow" if summary["chunks"]["partial"] else "green"
    out.print(f"[bold]{escape(str(title))}[/]: {summary['overall']['runs']} runs from [{colour}]{summary['status']}[/]")
    out.print(outcome_table(summary, out))
    for table in metric_tables(summary, out):
        out.print(table)
    if plot is not None:
        out.print(f"Plot written to {escape(str(plot))}.")
