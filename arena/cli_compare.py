"""``arena compare``: two benchmark runs of the same episodes side by side.

Registered on the app by :mod:`arena.cli`; errors are raised as :class:`ArenaError` and printed
as one line there.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from arena.cli_common import console
from arena.eval.stats import Estimate

#: How each default metric is printed.
_FORMATS = {
    "success": "{:.0%}", "collisions": "{:.2f}", "time_to_goal": "{:.1f}",
    "path_length": "{:.1f}", "min_distance_to_person": "{:.2f}",
    "personal_space_compliance": "{:.0%}",
}


def compare(
    run_a: Annotated[Path, typer.Argument(help="a benchmark run folder (from arena bench)")],
    run_b: Annotated[Path, typer.Argument(help="a run of the same suite, seed and scale")],
    metric: Annotated[
        list[str] | None,
        typer.Option("--metric", "-m", help="metric to compare (repeatable) \\[default: "
                     "success, collisions, time_to_goal, path_length, min_distance_to_person, "
                     "personal_space_compliance]"),
    ] = None,
    changes: Annotated[
        int, typer.Option(min=0, help="episodes with a changed outcome to list")
    ] = 20,
) -> None:
    """Compare two runs episode by episode: means, paired difference B − A, outcome changes.

    A difference marked * has a 95 % bootstrap interval of the paired differences that excludes
    0. Typical use: the same suite and contest on two simulators
    (``arena bench quick --simulator mujoco``).
    """
    from arena.eval.compare import (
        DEFAULT_METRICS,
        compare_runs,
        fmt_estimate,
        outcome_changes,
        pair_runs,
    )

    pair = pair_runs(run_a, run_b)
    rows = compare_runs(pair, metric or DEFAULT_METRICS)
    sim_a, sim_b = pair.simulators
    n = {r.contestant: r.a.n for r in rows}
    table = Table(title=f"A: {run_a} ({sim_a})  ·  B: {run_b} ({sim_b})", title_justify="left")
    for name, justify in (("contestant", "left"), ("metric", "left"), ("A", "right"),
                          ("B", "right"), ("B − A [95 % CI]", "right")):
        table.add_column(name, justify=justify)  # type: ignore[arg-type]
    last = None
    for r in rows:
        spec = _FORMATS.get(r.metric, "{:.3g}")
        mark = " *" if r.significant else ""
        who = f"{r.contestant} ({n[r.contestant]})" if r.contestant != last else ""
        if r.contestant != last and last is not None:
            table.add_section()
        last = r.contestant
        table.add_row(who, r.metric, fmt_estimate(_mean(r.a), spec),
                      fmt_estimate(_mean(r.b), spec),
                      fmt_estimate(r.diff, spec.replace("{:", "{:+")) + mark)
    console.print(table)
    console.print("(n): paired episodes · *: the interval excludes 0")
    moved = outcome_changes(pair)
    console.print(f"{len(moved)} of {len(pair.keys)} paired episodes changed outcome (A → B)"
                  + (":" if moved and changes else ""))
    for c in moved[:changes]:
        console.print(f"  {c.contestant} · {c.stage} · episode {c.episode}: {c.a} → {c.b}")
    if len(moved) > changes:
        console.print(f"  … {len(moved) - changes} more")


def _mean(e: Estimate) -> Estimate:
    """``e`` without its interval (the table gives the means; the interval is the difference's)."""
    return Estimate(e.n, e.mean, float("nan"), float("nan"), e.confidence)
