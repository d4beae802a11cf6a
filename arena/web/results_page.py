"""The results page (``/runs/{run}``): the report's tables and figures, drawn in the browser.

The data is :func:`arena.web.results.run_view` (the same as ``GET /api/runs/{run}/summary``):
the headline table (mean [95 % interval] per stage and contestant), one bar chart per headline
metric with its intervals for the stage picked above the charts, the outcomes, the social
radar, every other metric in a folded table, and the episodes with a replay link each. Charts
are ECharts (bundled with NiceGUI); the option builders are plain functions (tested without a
browser). Everything taken from a run's files is HTML-escaped.
"""

from __future__ import annotations

import html
import math
from collections.abc import Mapping, Sequence
from typing import Any
from urllib.parse import quote

from nicegui import ui

from arena.eval.plots import COLORS
from arena.web.results import run_view
from arena.web.store import NotFound, RunStore

#: Episode columns shown first, when a run has them.
COLUMNS = ("contestant", "stage", "episode", "index", "map", "outcome", "time", "path_length",
           "collisions", "success", "min_distance_to_person")

#: Error bars of a bar chart: a vertical line with caps at each category (x = index, lo, hi).
ERROR_BARS_JS = """(params, api) => {
  const x = api.value(0), lo = api.coord([x, api.value(1)]), hi = api.coord([x, api.value(2)]);
  const w = api.size([1, 0])[0] * 0.12, s = {stroke: '#222', lineWidth: 1.5};
  return {type: 'group', children: [
    {type: 'line', shape: {x1: lo[0], y1: lo[1], x2: hi[0], y2: hi[1]}, style: s},
    {type: 'line', shape: {x1: lo[0] - w, y1: lo[1], x2: lo[0] + w, y2: lo[1]}, style: s},
    {type: 'line', shape: {x1: hi[0] - w, y1: hi[1], x2: hi[0] + w, y2: hi[1]}, style: s}]};
}"""


def _num(x: float | None, digits: int = 3) -> str:
    return "–" if x is None or not math.isfinite(x) else f"{x:.{digits}g}"


def cell(est: Mapping[str, Any] | None) -> str:
    """``mean [lower, upper]`` (HTML) of one estimate; the interval only when it has one."""
    if not est or est.get("mean") is None:
        return "–"
    text = _num(est["mean"])
    if est.get("lower") is not None and est.get("upper") is not None:
        text += f' <span class="iv">[{_num(est["lower"])}, {_num(est["upper"])}]</span>'
    return text


def metric_title(entry: Mapping[str, Any]) -> str:
    """``label [unit] ↑`` (↑: higher is better, ↓: lower is better)."""
    label = entry.get("label") or str(entry["metric"]).replace("_", " ")
    unit = entry.get("unit") or ""
    arrow = {True: " ↑", False: " ↓", None: ""}[entry.get("higher")]
    return label + (f" [{unit}]" if unit and unit not in ("1", "-") and "[" not in label else "") \
        + arrow


def bar_options(view: Mapping[str, Any], metric: Mapping[str, Any], stage: str
                ) -> dict[str, Any]:
    """ECharts options: ``metric``'s mean per contestant on ``stage`` with interval bars."""
    rows = {r["contestant"]: r for r in view["summary"]
            if r["metric"] == metric["metric"] and r["stage"] == stage}
    names = list(view["contestants"])
    bars = [{"value": (rows.get(c) or {}).get("mean"),
             "itemStyle": {"color": COLORS[i % len(COLORS)]}} for i, c in enumerate(names)]
    errors = [[i, rows[c]["lower"], rows[c]["upper"]] for i, c in enumerate(names)
              if c in rows and rows[c]["lower"] is not None and rows[c]["upper"] is not None]
    return {
        "title": {"text": metric_title(metric), "left": "center",
                  "textStyle": {"fontSize": 13}},
        "grid": {"left": 48, "right": 12, "top": 34, "bottom": 28},
        "tooltip": {"trigger": "axis", "axisPointer": {"type": "shadow"}},
        "animation": False,
        "xAxis": {"type": "category", "data": names, "axisLabel": {"interval": 0}},
        "yAxis": {"type": "value", "scale": False},
        "series": [
            {"type": "bar", "data": bars, "barWidth": "50%", "name": "mean"},
            {"type": "custom", "name": "95 % interval", "data": errors,
             ":renderItem": ERROR_BARS_JS, "z": 10,
             "tooltip": {"show": False},
             "encode": {"x": 0, "y": [1, 2]}},  # the axis covers the intervals too
        ],
    }


def outcome_options(view: Mapping[str, Any]) -> dict[str, Any]:
    """ECharts options: episodes per outcome, stacked per contestant."""
    kinds = sorted({o for counts in view["outcomes"].values() for o in counts},
                   key=lambda o: (o != "success", o))
    palette = {"success": "#2ca02c", "collision": "#d62728", "timeout": "#ff7f0e",
               "error": "#7f7f7f"}
    names = list(view["contestants"])
    return {
        "title": {"text": "Outcomes [episodes]", "left": "center", "textStyle": {"fontSize": 13}},
        "animation": False,
        "legend": {"bottom": 0},
        "grid": {"left": 90, "right": 16, "top": 34, "bottom": 40},
        "tooltip": {"trigger": "axis", "axisPointer": {"type": "shadow"}},
        "xAxis": {"type": "value"},
        "yAxis": {"type": "category", "data": names},
        "series": [{"type": "bar", "stack": "all", "name": k,
                    "itemStyle": {"color": palette.get(k, "#9467bd")},
                    "data": [view["outcomes"][c].get(k, 0) for c in names]} for k in kinds],
    }


def radar_options(radar: Mapping[str, Any]) -> dict[str, Any]:
    """ECharts options: the social radar (1 = the best end of each metric's fixed range)."""
    return {
        "title": {"text": "Social metrics (outer ring = best)", "left": "center",
                  "textStyle": {"fontSize": 13}},
        "animation": False,
        "legend": {"bottom": 0},
        "tooltip": {},
        "radar": {"indicator": [
            {"name": m.replace("_", " ") + (" ↑" if up else " ↓"), "max": 1.0, "min": 0.0}
            for m, up in zip(radar["metrics"], radar["higher"], strict=True)],
            "radius": "62%", "axisName": {"fontSize": 10}},
        "series": [{"type": "radar", "data": [
            {"name": c, "value": [0.0 if v is None else v for v in values],
             "itemStyle": {"color": COLORS[i % len(COLORS)]}, "areaStyle": {"opacity": 0.12}}
            for i, (c, values) in enumerate(zip(radar["contestants"], radar["values"],
                                                strict=True))]}],
    }


def headline_html(view: Mapping[str, Any]) -> str:
    """The headline table: one row per stage × contestant, one column per headline metric."""
    index = {(r["stage"], r["contestant"], r["metric"]): r for r in view["summary"]}
    head = "".join(f"<th>{html.escape(metric_title(m))}</th>" for m in view["headline"])
    rows = []
    for stage in view["stages"]:
        for c in view["contestants"]:
            first = index.get((stage, c, view["headline"][0]["metric"])) if view["headline"] \
                else None
            if first is None:
                continue
            cells = "".join(f"<td>{cell(index.get((stage, c, m['metric'])))}</td>"
                            for m in view["headline"])
            rows.append(f"<tr><td>{html.escape(stage)}</td><td>{html.escape(c)}</td>"
                        f"<td>{first['n']}</td>{cells}</tr>")
    return (f'<table class="arena-table" id="results-headline"><tr><th>stage</th>'
            f"<th>contestant</th><th>n</th>{head}</tr>{''.join(rows)}</table>")


def metrics_html(view: Mapping[str, Any]) -> str:
    """Every other metric over all stages: one row per metric, one column per contestant."""
    names = list(view["contestants"])
    head = "".join(f"<th>{html.escape(c)}</th>" for c in names)
    rows = []
    for m in view["metrics"]:
        by = {r["contestant"]: r for r in m["rows"]}
        cells = "".join(f"<td>{cell(by.get(c))}</td>" for c in names)
        rows.append(f"<tr><td>{html.escape(metric_title(m))}</td>{cells}</tr>")
    return f'<table class="arena-table"><tr><th>metric</th>{head}</tr>{"".join(rows)}</table>'


def episodes_html(run: str, rows: Sequence[Mapping[str, Any]]) -> str:
    """The episodes, one row each, with a replay link where the episode has a record."""
    cols = [c for c in COLUMNS if c in rows[0]]
    head = "".join(f"<th>{c}</th>" for c in cols) + "<th></th>"
    body = []
    for row in rows:
        rec = str(row.get("record") or "")
        link = (f'<a href="/replay/{quote(run)}?record={quote(rec)}">replay</a>'
                if rec.endswith(".parquet") else "")
        outcome = html.escape(str(row.get("outcome", "")))
        body.append(f'<tr class="o-{outcome}">'
                    + "".join(f"<td>{_episode_cell(row.get(c, ''))}</td>" for c in cols)
                    + f"<td>{link}</td></tr>")
    return (f'<table class="arena-table" id="results-episodes"><tr>{head}</tr>'
            f"{''.join(body)}</table>")


def _episode_cell(value: Any) -> str:
    if isinstance(value, float):
        if not math.isfinite(value):
            return "–"
        return str(int(value)) if value.is_integer() and abs(value) < 1e9 else f"{value:.3g}"
    return html.escape(str(value))


def results_page(store: RunStore, run: str) -> None:
    """The page's body for run ``run`` of ``store`` (header, table styles: the caller's)."""
    try:
        info = store.info(run)
        view = run_view(store, run)
        rows = store.results(run)
        report = store.folder(run) / "report" / "report.html"
    except NotFound as e:
        ui.label(str(e)).classes("text-red-700")
        return
    with ui.row().classes("items-center gap-4"):
        ui.label(f"{info.kind} · {info.title} · {view['episodes']} episode(s)").classes(
            "text-slate-600")
        if info.live:
            ui.link("watch it live", f"/live/{quote(run)}")
        if report.is_file():  # written by arena report / bench --report
            ui.link("HTML report", f"/api/runs/{quote(run)}/files/report/report.html",
                    new_tab=True)
    if not view["episodes"]:
        ui.label("No finished episode yet.")
        return
    ui.label("Headline metrics: mean [95 % bootstrap interval]").classes("text-lg mt-2")
    ui.html(headline_html(view), sanitize=False).classes("w-full overflow-x-auto")
    charts: list[tuple[Any, dict[str, Any]]] = []
    stage = view["stages"][-1]
    if view["headline"]:
        with ui.row().classes("items-center gap-2 mt-2"):
            ui.label("stage:")
            toggle = ui.toggle(view["stages"], value=stage).props("id=results-stage no-caps")
        with ui.element("div").classes("w-full").style(
                "display:grid;grid-template-columns:repeat(auto-fill,minmax(330px,1fr));gap:8px"):
            for m in view["headline"]:
                chart = ui.echart(bar_options(view, m, stage)).style("height:260px")
                charts.append((chart, m))

        def show_stage(e: Any) -> None:
            for chart, m in charts:
                chart.options.clear()
                chart.options.update(bar_options(view, m, e.value))
                chart.update()

        toggle.on_value_change(show_stage)
    with ui.row().classes("w-full gap-2"):
        ui.echart(outcome_options(view)).style("height:260px;flex:1;min-width:330px")
        if view["radar"]:
            ui.echart(radar_options(view["radar"])).style("height:360px;flex:1;min-width:330px")
    if view["metrics"]:
        with ui.expansion("All other metrics (all stages)").classes("w-full"):
            ui.html(metrics_html(view), sanitize=False).classes("w-full overflow-x-auto")
    ui.label("Episodes").classes("text-lg mt-2")
    if rows:
        ui.html(episodes_html(run, rows), sanitize=False).classes("w-full overflow-x-auto")

