"""``arena bench`` and ``arena report``: benchmark runs, their tables and HTML reports.

Registered on the app by :mod:`arena.cli`; errors are raised as :class:`ArenaError` and printed
as one line there.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from enum import StrEnum
from pathlib import Path
from typing import Annotated

import typer
from rich.table import Table

from arena.cli_common import PluginOption, console, err_console, load_plugin_options
from arena.core.errors import ArenaError, ConfigError


class BenchBackend(StrEnum):
    """Where ``arena bench`` runs its episodes."""

    process = "process"
    ray = "ray"


def bench(
    suite: Annotated[str, typer.Argument(help="packaged suite name (paper, quick) or YAML path")],
    contest: Annotated[
        str | None,
        typer.Option(
            help="packaged contest name or YAML path \\[default: basic; resume: the run's]"
        ),
    ] = None,
    workers: Annotated[
        int, typer.Option("--workers", "-j", help="worker processes (0: in this process, for "
                          "debugging: no fault isolation); ray: tasks at once")
    ] = 1,
    backend: Annotated[
        BenchBackend,
        typer.Option(help="process pool, or ray tasks (pip install 'arena\\[ray]'); "
                          "a run resumes with either"),
    ] = BenchBackend.process,
    ray_address: Annotated[
        str | None,
        typer.Option(help="ray: connect to this cluster ('auto' or an address) "
                          "\\[default: start a local Ray with --workers CPUs]"),
    ] = None,
    resume: Annotated[
        Path | None, typer.Option("--resume", help="resume the run in this folder")
    ] = None,
    out: Annotated[Path | None, typer.Option("--out", "-o", help="run folder")] = None,
    scale: Annotated[
        float | None,
        typer.Option(
            help="scale_episodes: factor on every stage \\[default: 1; resume: the run's]"
        ),
    ] = None,
    seed: Annotated[
        int | None, typer.Option(help="run seed \\[default: 0; resume: the run's]")
    ] = None,
    progress: Annotated[
        bool, typer.Option("--progress/--no-progress", help="show a progress bar")
    ] = True,
    report: Annotated[
        bool, typer.Option("--report/--no-report", help="then write the HTML report (RUN/report)")
    ] = False,
    worlds: Annotated[
        Path | None,
        typer.Option("--worlds", metavar="DIR",
                     help="folder of worlds in Arena's layout (<world>/map/map.yaml, e.g. "
                          "arena-simulation-setup/worlds): the suite's world names are looked "
                          "up there first \\[default: the suite's worlds key; resume: the run's]"),
    ] = None,
    plugin: PluginOption = None,
    simulator: Annotated[
        str | None,
        typer.Option("--simulator", metavar="TYPE",
                     help="simulator backend of every episode (sim.backend.type: native2d, "
                          "mujoco) \\[default: native2d; resume: the run's]"),
    ] = None,
    episode_timeout: Annotated[
        float | None,
        typer.Option("--episode-timeout", metavar="SECONDS",
                     help="wall-clock limit of one episode: past it, its worker is killed and "
                          "the episode ends as error (0: no limit) \\[default: 600]"),
    ] = None,
    live: Annotated[
        bool, typer.Option("--live", help="watch the workers' episodes in the browser: the web "
                           "app on 127.0.0.1 (pip install 'arena\\[web]'); watching only, it "
                           "changes no result")
    ] = False,
    port: Annotated[int, typer.Option(help="--live: the web app's port")] = 8080,
    web: Annotated[
        bool, typer.Option("--web/--no-web", help="--live: start the web app, or only serve "
                           "the workers' channels (a web app on the run's folder shows them)")
    ] = True,
) -> None:
    """Benchmark: every contestant on every episode of a suite; resumable, parallel.

    Results land in the run folder (``episodes/<contestant>/<stage>/<episode>.parquet|json``,
    ``run.json``); a killed run continues with ``--resume RUN_DIR``. An episode whose worker
    dies (a crashing planner) or that runs past ``--episode-timeout`` ends as ``error``; the
    run goes on. With ``--live`` the web app shows each worker's current episode.
    """
    import math
    import warnings
    from datetime import datetime

    from pydantic import ValidationError

    from arena.config.schema import ExperimentConfig
    from arena.core.errors import ConfigError
    from arena.eval.runner import run_benchmark
    from arena.eval.store import MANIFEST_DEFAULTS, load_results, read_manifest

    load_plugin_options(plugin)
    if resume is not None:
        manifest = read_manifest(resume)  # checked: a bad field is a one-line error
        contest = contest if contest is not None else str(manifest["contest"])
        seed = seed if seed is not None else int(manifest["seed"])
        scale = scale if scale is not None else float(manifest["scale"])
        if worlds is None and manifest.get("worlds") is not None:
            worlds = Path(str(manifest["worlds"]))
        if simulator is None:  # a run from before the key: native2d
            simulator = str(manifest.get("simulator", MANIFEST_DEFAULTS["simulator"]))
    contest = contest if contest is not None else "basic"
    seed = seed if seed is not None else 0
    scale = scale if scale is not None else 1.0
    if not (math.isfinite(scale) and scale > 0):
        raise ArenaError(f"--scale: expected a finite number > 0, got {scale}")
    if workers < (1 if backend is BenchBackend.ray else 0):
        raise ArenaError(f"--workers: expected an integer >= "
                         f"{1 if backend is BenchBackend.ray else 0}, got {workers}")
    limit = {}  # the runner's default unless given
    if episode_timeout is not None:
        if not (math.isfinite(episode_timeout) and episode_timeout >= 0):
            raise ArenaError(f"--episode-timeout: expected seconds >= 0 (0: no limit), "
                             f"got {episode_timeout}")
        if workers == 0 and episode_timeout and backend is BenchBackend.process:
            raise ArenaError("--episode-timeout: an episode in this process (--workers 0) "
                             "cannot be stopped; use --workers 1 or more")
        limit["episode_timeout"] = episode_timeout or None
    simulator = simulator if simulator is not None else "native2d"
    try:
        base_cfg = ExperimentConfig(seed=seed, sim={"backend": {"type": simulator}})
    except ValidationError as e:  # the schema says what a seed must be
        raise ConfigError(f"{e.errors()[0]['msg']} (got {seed})", source="--seed") from None
    from arena.sim.backend import BACKENDS

    BACKENDS.validate(base_cfg.sim.backend, source="--simulator")
    if resume is not None and out is not None and resume.resolve() != out.resolve():
        raise ArenaError("give either --resume RUN_DIR or -o RUN_DIR, not two different folders")
    if out is not None and out.exists() and not out.is_dir():
        raise ArenaError(f"-o/--out: {out} is a file; expected a run folder (new or empty)")
    run_dir = resume or out
    if run_dir is None:
        name = Path(contest).stem
        run_dir = Path("runs") / f"bench_{name}_{datetime.now().strftime('%y-%m-%d_%H-%M-%S')}"
    if live and backend is BenchBackend.ray:
        raise ArenaError("--live works with the process backend (--backend process)")
    with warnings.catch_warnings(), _live_web(run_dir, live and web, port):
        # one line per warning (a stage the scale drops ...), not Python's two with a source line
        warnings.showwarning = lambda message, *args, **kwargs: err_console.print(
            f"[yellow]warning:[/] {message}", highlight=False, soft_wrap=True)
        run = run_benchmark(
            suite, contest, run_dir, base_cfg=base_cfg, workers=workers,
            resume=resume is not None, scale=scale, progress=progress, backend=backend.value,
            ray_address=ray_address, worlds=worlds, live=live, **limit,
        )
    _print_bench_tables(load_results(run), f"{suite} · {Path(contest).stem} · seed {seed}")
    console.print(f"run folder: {run}")
    if report:
        _write_report(run, None, videos=1, workers=workers)


@contextlib.contextmanager
def _live_web(run_dir: Path, live: bool, port: int) -> Iterator[None]:
    """With ``live``: the web app on the run's parent folder while the benchmark runs."""
    if not live:
        yield
        return
    from arena.web.server import require_web, serve_subprocess

    require_web()
    run_dir.parent.mkdir(parents=True, exist_ok=True)
    web = serve_subprocess(run_dir.parent, port=port)
    try:
        console.print(f"live view:   {web.url}/live/{run_dir.name}", highlight=False,
                      soft_wrap=True)
        yield
    finally:
        web.stop()


#: Columns of the per-contestant table ``arena bench`` prints: (metric, header, format).
_BENCH_COLUMNS = (
    ("success", "success", "{:.0%}"),  # headers fit an 80-column terminal
    ("collisions", "coll.\n/ep", "{:.2f}"),
    ("time_to_goal", "t goal\n(s)", "{:.1f}"),
    ("path_length", "path\n(m)", "{:.1f}"),
    ("min_distance_to_person", "min d.\n(m)", "{:.2f}"),
    ("personal_space_compliance", "pers.\nspace", "{:.0%}"),
    ("cf_displacement_mean", "cf disp\n(m)", "{:.3f}"),
)


def _print_bench_tables(results: object, title: str) -> None:
    """Print the per-contestant means (all episodes) and the success rate per stage."""
    import numpy as np

    from arena.eval import plots
    from arena.eval.tables import summary_table

    cols = plots.as_columns(results)
    n = len(cols["contestant"])
    pooled = {**cols, "stage": np.full(n, "all")}
    names = [m for m, _, _ in _BENCH_COLUMNS if m in cols]
    means = {(r.contestant, r.metric): r.mean for r in summary_table(pooled, names)}
    contestants = plots.unique_in_order(cols["contestant"])
    from rich import box

    from arena.eval.metrics import MetricParams

    # the radius the metrics were computed with (the runner uses the default parameters)
    radius = MetricParams().personal_space_radius
    table = Table(
        title=f"arena bench · {title} · mean over all episodes", box=box.SIMPLE_HEAD,
        caption="min d.: smallest body gap to a person · pers. space: share of steps with "
        f"no body gap to a person below {radius:g} m · cf disp: how far people were from where "
        "they would have walked without the robot",
    )
    table.add_column("contestant", no_wrap=True)
    table.add_column("n", justify="right")
    for m, header, _ in _BENCH_COLUMNS:
        if m in cols:
            table.add_column(header, justify="right",
                             min_width=max(len(line) for line in header.split("\n")))
    errors = cols["outcome"].astype(str) == "error"
    for c in contestants:
        mine = cols["contestant"] == c
        cells = [c, f"{int(mine.sum())}" + (f" ({int(errors[mine].sum())} err)"
                                            if errors[mine].any() else "")]
        for m, _, fmt in _BENCH_COLUMNS:
            if m in cols:
                v = means[(c, m)]
                cells.append(fmt.format(v) if np.isfinite(v) else "–")
        table.add_row(*cells)
    console.print(table)
    stages = plots.unique_in_order(cols["stage"])
    per_stage = Table(title="success per stage (episodes)", box=box.SIMPLE_HEAD)
    per_stage.add_column("stage")
    for c in contestants:
        per_stage.add_column(c, justify="right")
    for st in stages:
        row = [st]
        for c in contestants:
            mask = (cols["contestant"] == c) & (cols["stage"] == st)
            ok = int((cols["outcome"][mask].astype(str) == "success").sum())
            row.append(f"{ok}/{int(mask.sum())}")
        per_stage.add_row(*row)
    console.print(per_stage)


def _write_report(run: Path, out: Path | None, *, videos: int, workers: int) -> None:
    from arena.eval.report import main as write_run_report

    if not (run / "run.json").is_file():
        raise ConfigError(f"{run}: not a benchmark run folder (no run.json); run arena bench")
    with console.status("writing the report (figures, videos) ..."):
        paths = write_run_report(run, out, video_episodes=videos, workers=workers)
    for kind in ("html", "csv", "tex"):
        console.print(f"{kind + ':':6} {paths[kind]}")
    console.print(f"figures: {paths['figures']} (PDF and SVG)")


def report(
    run: Annotated[Path, typer.Argument(help="a benchmark run folder (from arena bench)")],
    out: Annotated[
        Path | None, typer.Option("-o", "--out", help="output folder (default RUN/report)")
    ] = None,
    videos: Annotated[
        int, typer.Option(min=0, help="episodes re-simulated as videos (each for every "
                          "contestant), picked where the contestants differ most")
    ] = 1,
    workers: Annotated[
        int, typer.Option("--workers", "-j", min=1, help="processes rendering videos")
    ] = 1,
) -> None:
    """Write one self-contained HTML report and CSV/LaTeX tables for a benchmark run."""
    _write_report(run, out, videos=videos, workers=workers)
