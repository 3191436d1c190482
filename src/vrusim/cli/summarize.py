"""`vrusim summarize`: collision probability and metric statistics of a sweep's results, overall and per group."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer
from rich import box
from rich.markup import escape
from rich.table import Table

from vrusim.cli.options import JsonOption, split_names
from vrusim.cli.output import console, print_json, user_errors

_STAT_TITLES = {"count": "n", "mean": "mean", "std": "std", "min": "min", "p5": "p5", "median": "median",
                "p95": "p95", "max": "max"}  # fmt: skip


def _num(value: float | None) -> str:
    return "–" if value is None else f"{value:.4g}"


def _key_text(value: Any) -> str:
    """A group's value of one column: the bin as low–high (and centre), or the value."""
    if value is None:
        return "null"
    if isinstance(value, dict):
        return f"{value['low']:.4g}–{value['high']:.4g} (≈{value['centre']:.4g})"
    return f"{value:.6g}" if isinstance(value, float) else str(value)


def _by_header(described: dict[str, Any]) -> str:
    name = escape(described["name"])
    return f"{name}\n{len(described['edges']) - 1} equal-width bins" if described["binned"] else name


def outcome_table(summary: dict[str, Any]) -> Table:
    """Runs, collisions, P(collision) and its Wilson 95 % interval: one row per group (or overall)."""
    table = Table(title="Collisions (Wilson 95 % interval)", box=box.SIMPLE_HEAD, title_justify="left")
    for described in summary["by"]:
        table.add_column(_by_header(described))
    for name in ("Runs", "Collisions", "P(collision)", "95 % interval"):
        table.add_column(name, justify="right", no_wrap=True)
    rows = summary["groups"] if summary["by"] else [summary["overall"]]
    for row in rows:
        low, high = row["collision_probability_95"]
        probability = row["collision_probability"]
        style = "red" if row["collisions"] else "green"
        table.add_row(
            *(escape(_key_text(row["key"][d["name"]])) for d in summary["by"]),
            str(row["runs"]),
            f"[{style}]{row['collisions']}[/]",
            _num(probability),
            f"{low:.3f}–{high:.3f}",
        )
    return table


def metric_tables(summary: dict[str, Any]) -> list[Table]:
    """Without groups one table, a row per metric; with groups one table per metric, a row per group."""
    if not summary["metrics"]:
        return []
    if not summary["by"]:
        table = Table(title="Metrics (all runs)", box=box.SIMPLE_HEAD, title_justify="left")
        table.add_column("Metric", no_wrap=True)
        for title in _STAT_TITLES.values():
            table.add_column(title, justify="right")
        for metric in summary["metrics"]:
            stats = summary["overall"]["metrics"][metric]
            table.add_row(escape(metric), str(stats["count"]), *(_num(stats[s]) for s in list(_STAT_TITLES)[1:]))
        return [table]
    tables = []
    for metric in summary["metrics"]:
        table = Table(title=escape(metric), box=box.SIMPLE_HEAD, title_justify="left")
        for described in summary["by"]:
            table.add_column(_by_header(described))
        for title in _STAT_TITLES.values():
            table.add_column(title, justify="right")
        for group in summary["groups"]:
            stats = group["metrics"][metric]
            table.add_row(
                *(escape(_key_text(group["key"][d["name"]])) for d in summary["by"]),
                str(stats["count"]),
                *(_num(stats[s]) for s in list(_STAT_TITLES)[1:]),
            )
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
            check_plot_path(plot)
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
    out.print(outcome_table(summary))
    for table in metric_tables(summary):
        out.print(table)
    if plot is not None:
        out.print(f"Plot written to {escape(str(plot))}.")
