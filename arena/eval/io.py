"""Store :class:`~arena.eval.record.EpisodeRecord` as Parquet, and export Arena's CSV layout.

Parquet layout (:func:`save_record`): ONE file, one table with one row per robot row (``T``
rows). Robot columns are plain: ``time, x, y, theta, vx, vy, omega, cmd_vx, cmd_vy, cmd_omega,
min_range`` (float64) and ``collision_wall, collision_obstacle, collision_pedestrian,
collision_robot`` (bool). The pedestrian table (``K`` rows, long format) is stored in the same
file as list columns, each robot row holding the pedestrians of that step: ``ped_id, ped_kind,
ped_state`` (list<int64>), ``ped_x, ped_y, ped_vx, ped_vy, ped_heading, ped_radius``
(list<float64>), and, when the record has a counterfactual crowd, ``ped_cf_x, ped_cf_y``
(list<float64>, NaN where the replay lacks the person); when the stack planned on detected
people (:class:`~arena.eval.record.PerceptionRecord`), ``perceived`` (bool), ``ped_seen``
(list<bool>, beside the other pedestrian lists), ``trk_id`` (list<int64>), ``trk_x, trk_y``
and ``det_x, det_y`` (list<float64>, the tracks and detections of the row). ``ped_row`` is
implied by the list a pedestrian sits in. The meta data (with the resolved config) and the
events are JSON in the schema metadata under ``arena.meta`` and ``arena.events`` (plus
``arena.format`` = ``"episode-record/1"``).

The round trip is exact (values and dtypes) for records whose pedestrian rows are grouped by
step in increasing ``ped_row`` order, which is what :class:`~arena.eval.recorder.Recorder`
produces; other records come back with their pedestrian rows stably sorted by ``ped_row``.

Arena CSV export (:func:`export_arena_csv`): see its docstring.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
from numpy.typing import NDArray

from arena.core.errors import ConfigError
from arena.eval.record import EpisodeMeta, EpisodeRecord, PerceptionRecord

FORMAT = "episode-record/1"
_ROBOT_FLOATS = ("time", "x", "y", "theta", "vx", "vy", "omega",
                 "cmd_vx", "cmd_vy", "cmd_omega", "min_range")
_COLLISIONS = ("collision_wall", "collision_obstacle", "collision_pedestrian", "collision_robot")
_PED_INTS = ("ped_id", "ped_kind", "ped_state")
_PED_FLOATS = ("ped_x", "ped_y", "ped_vx", "ped_vy", "ped_heading", "ped_radius")
_PED_CF = ("ped_cf_x", "ped_cf_y")

#: Arena's recorder writes ``secs × 10e9 + nsecs`` (10e9 = 1e10, a quirk); its metrics divide
#: by 1e10. We write ``round(seconds × 1e10)`` so that Arena's division gives back seconds.
ARENA_TIME_SCALE = 1e10
#: Arena's ``record_frequency`` (data_recorder_config.yaml), s.
ARENA_RECORD_PERIOD = 0.4


def _meta_to_json(meta: EpisodeMeta) -> dict[str, Any]:
    return {
        "episode": meta.episode,
        "seed": meta.seed,
        "stage": meta.stage,
        "map_name": meta.map_name,
        "robot": meta.robot,
        "robot_radius": meta.robot_radius,
        "start": [float(v) for v in meta.start],
        "goal": [float(v) for v in meta.goal],
        "goal_radius": meta.goal_radius,
        "goal_tolerance_angle": meta.goal_tolerance_angle,
        "time_limit": meta.time_limit,
        "dt": meta.dt,
        "outcome": meta.outcome,
        "config": meta.config,
    }


def _meta_from_json(d: dict[str, Any]) -> EpisodeMeta:
    gta = d["goal_tolerance_angle"]
    return EpisodeMeta(
        episode=int(d["episode"]),
        seed=int(d["seed"]),
        stage=str(d["stage"]),
        map_name=str(d["map_name"]),
        robot=str(d["robot"]),
        robot_radius=float(d["robot_radius"]),
        start=np.asarray(d["start"], dtype=np.float64),
        goal=np.asarray(d["goal"], dtype=np.float64),
        goal_radius=float(d["goal_radius"]),
        goal_tolerance_angle=None if gta is None else float(gta),
        time_limit=float(d["time_limit"]),
        dt=float(d["dt"]),
        outcome=str(d["outcome"]),
        config=d.get("config") or {},
    )


def _list_column(values: NDArray[Any], offsets: NDArray[np.int32], typ: pa.DataType) -> pa.Array:
    return pa.ListArray.from_arrays(pa.array(offsets, pa.int32()), pa.array(values, typ))


def record_to_table(record: EpisodeRecord) -> pa.Table:
    """The record as one Arrow table (``T`` rows) with the metadata attached (module doc)."""
    r = record
    t = r.steps
    order = np.argsort(r.ped_row, kind="stable")
    counts = np.bincount(r.ped_row, minlength=t) if r.ped_row.size else np.zeros(t, np.int64)
    offsets = np.zeros(t + 1, dtype=np.int32)
    np.cumsum(counts, out=offsets[1:])
    robot = np.column_stack([r.time, r.pose, r.velocity, r.command, r.min_range])
    cols: dict[str, pa.Array] = {
        name: pa.array(np.ascontiguousarray(robot[:, j]), pa.float64())
        for j, name in enumerate(_ROBOT_FLOATS)
    }
    for name in _COLLISIONS:
        cols[name] = pa.array(getattr(r, name), pa.bool_())
    ints = {"ped_id": r.ped_id, "ped_kind": r.ped_kind, "ped_state": r.ped_state}
    for name in _PED_INTS:
        cols[name] = _list_column(ints[name][order].astype(np.int64), offsets, pa.int64())
    floats = np.column_stack([r.ped_position, r.ped_velocity, r.ped_heading, r.ped_radius])
    for j, name in enumerate(_PED_FLOATS):
        cols[name] = _list_column(np.ascontiguousarray(floats[order, j]), offsets, pa.float64())
    if r.ped_cf_position is not None:
        for j, name in enumerate(_PED_CF):
            cols[name] = _list_column(
                np.ascontiguousarray(r.ped_cf_position[order, j]), offsets, pa.float64()
            )
    if r.perception is not None:
        cols.update(_perception_columns(r.perception, order, offsets, t))
    meta = {
        "arena.format": FORMAT,
        "arena.meta": json.dumps(_meta_to_json(r.meta)),
        "arena.events": json.dumps([list(e) for e in r.events]),
    }
    return pa.table(cols).replace_schema_metadata(meta)


def _offsets(rows: NDArray[np.int64], t: int) -> tuple[NDArray[np.int64], NDArray[np.int32]]:
    """Stable order of long-format ``rows`` by row, and the list offsets ``(t + 1,)``."""
    order = np.argsort(rows, kind="stable")
    offsets = np.zeros(t + 1, dtype=np.int32)
    if rows.size:
        np.cumsum(np.bincount(rows, minlength=t), out=offsets[1:])
    return order, offsets


def _perception_columns(
    p: PerceptionRecord, ped_order: NDArray[np.int64], ped_offsets: NDArray[np.int32], t: int
) -> dict[str, pa.Array]:
    cols = {"perceived": pa.array(p.perceived, pa.bool_()),
            "ped_seen": _list_column(p.seen[ped_order], ped_offsets, pa.bool_())}
    order, offsets = _offsets(p.trk_row, t)
    cols["trk_id"] = _list_column(p.trk_id[order].astype(np.int64), offsets, pa.int64())
    for j, name in enumerate(("trk_x", "trk_y")):
        cols[name] = _list_column(np.ascontiguousarray(p.trk_position[order, j]), offsets,
                                  pa.float64())
    order, offsets = _offsets(p.det_row, t)
    for j, name in enumerate(("det_x", "det_y")):
        cols[name] = _list_column(np.ascontiguousarray(p.det_position[order, j]), offsets,
                                  pa.float64())
    return cols


def _perception_from(table: pa.Table) -> PerceptionRecord | None:
    if "perceived" not in table.column_names:
        return None

    def col(name: str) -> pa.Array:
        return table.column(name).combine_chunks()

    def rows(name: str) -> NDArray[np.int64]:
        counts = np.diff(col(name).offsets.to_numpy().astype(np.int64))
        return np.repeat(np.arange(table.num_rows, dtype=np.int64), counts)

    def flat(name: str, dtype: type) -> NDArray[Any]:
        out: NDArray[Any] = col(name).flatten().to_numpy(zero_copy_only=False).astype(dtype)
        return out

    return PerceptionRecord(
        perceived=col("perceived").to_numpy(zero_copy_only=False).astype(np.bool_),
        seen=flat("ped_seen", np.bool_),
        trk_row=rows("trk_id"), trk_id=flat("trk_id", np.int64),
        trk_position=np.column_stack([flat("trk_x", np.float64),
                                      flat("trk_y", np.float64)]).reshape(-1, 2),
        det_row=rows("det_x"),
        det_position=np.column_stack([flat("det_x", np.float64),
                                      flat("det_y", np.float64)]).reshape(-1, 2),
    )


def table_to_record(table: pa.Table) -> EpisodeRecord:
    """Inverse of :func:`record_to_table`."""
    md = {k.decode(): v.decode() for k, v in (table.schema.metadata or {}).items()}
    if md.get("arena.format") != FORMAT:
        raise ValueError(f"not an arena episode record (format {md.get('arena.format')!r})")
    meta = _meta_from_json(json.loads(md["arena.meta"]))
    events = [(float(e[0]), str(e[1]), str(e[2])) for e in json.loads(md["arena.events"])]

    def col(name: str) -> pa.Array:
        return table.column(name).combine_chunks()

    robot = np.column_stack(
        [col(n).to_numpy(zero_copy_only=False).astype(np.float64) for n in _ROBOT_FLOATS]
    ) if table.num_rows else np.zeros((0, len(_ROBOT_FLOATS)))
    coll = {n: col(n).to_numpy(zero_copy_only=False).astype(np.bool_) for n in _COLLISIONS}
    first = col("ped_id")
    offsets = first.offsets.to_numpy().astype(np.int64)
    counts = np.diff(offsets) if offsets.size else np.zeros(0, np.int64)
    ped_row = np.repeat(np.arange(table.num_rows, dtype=np.int64), counts)
    ints = {n: col(n).flatten().to_numpy(zero_copy_only=False).astype(np.int64)
            for n in _PED_INTS}
    fl = {n: col(n).flatten().to_numpy(zero_copy_only=False).astype(np.float64)
          for n in _PED_FLOATS}
    cf = None
    if _PED_CF[0] in table.column_names:
        cf = np.column_stack([
            col(n).flatten().to_numpy(zero_copy_only=False).astype(np.float64) for n in _PED_CF
        ]).reshape(-1, 2)
    return EpisodeRecord(
        meta=meta,
        time=robot[:, 0].copy(),
        pose=robot[:, 1:4].copy(),
        velocity=robot[:, 4:7].copy(),
        command=robot[:, 7:10].copy(),
        min_range=robot[:, 10].copy(),
        collision_wall=coll["collision_wall"],
        collision_obstacle=coll["collision_obstacle"],
        collision_pedestrian=coll["collision_pedestrian"],
        collision_robot=coll["collision_robot"],
        ped_row=ped_row,
        ped_id=ints["ped_id"],
        ped_kind=ints["ped_kind"],
        ped_state=ints["ped_state"],
        ped_position=np.column_stack([fl["ped_x"], fl["ped_y"]]).reshape(-1, 2),
        ped_velocity=np.column_stack([fl["ped_vx"], fl["ped_vy"]]).reshape(-1, 2),
        ped_heading=fl["ped_heading"],
        ped_radius=fl["ped_radius"],
        events=events,
        ped_cf_position=cf,
        perception=_perception_from(table),
    )


def save_record(record: EpisodeRecord, path: str | Path) -> Path:
    """Write ``record`` as one Parquet file (layout in the module doc); return the path."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    pq.write_table(record_to_table(record), p)
    return p


def load_record(path: str | Path) -> EpisodeRecord:
    """Read a file written by :func:`save_record`.

    Raises:
        ConfigError: the file is not such a record (corrupt, truncated, another table), naming
            the file: a record comes from a run folder, which may be damaged or foreign.
    """
    try:
        return table_to_record(pq.read_table(Path(path)))
    except (pa.ArrowException, OSError, ValueError, KeyError, TypeError, IndexError) as e:
        reason = str(e).splitlines()[0] if str(e) else type(e).__name__
        raise ConfigError(f"not a readable episode record ({reason})", source=str(path)) from None


# ---------------------------------------------------------------------------------------------
# Arena CSV export


def _r3(v: float) -> float:
    return round(float(v), 3)


def _sample_rows(time: NDArray[np.float64], period: float | None) -> NDArray[np.int64]:
    """Rows Arena's recorder would write.

    The first, then each row at least ``period`` s after the last written one (Arena writes when
    ``now - last ≥ record_frequency``).
    """
    if period is None or period <= 0 or time.size == 0:
        return np.arange(time.size, dtype=np.int64)
    rows = [0]
    last = float(time[0])
    eps = 1e-9
    for j in range(1, time.size):
        if float(time[j]) - last >= period - eps:
            rows.append(j)
            last = float(time[j])
    return np.asarray(rows, dtype=np.int64)


def export_arena_csv(
    record: EpisodeRecord,
    folder: str | Path,
    *,
    record_period: float | None = None,
    scan: NDArray[np.float64] | None = None,
    scan_range_max: float | None = None,
) -> dict[str, Path]:
    """Write the record in Arena's data-recorder CSV layout (arena_specs §4.1).

    Files (header row, one row per sample, the same row index across the files):

    - ``odom.csv``: ``time, data`` with ``{"position": [x, y, yaw], "velocity": [vx, vy, wz]}``
      (body-frame twist, rounded to 3 decimals).
    - ``cmd_vel.csv``: ``time, data`` with ``[vx, vy, omega]`` (rounded to 3).
    - ``pedsim_agents_data.csv``: ``time, data`` with a list of ``{"id", "type",
      "social_state", "position": [x, y], "theta", "destination": [x, y]}``. ``id`` is our
      integer id as a string (Arena's ids are strings), ``type`` and ``social_state`` our
      integer codes, ``theta`` our pedestrian heading (Arena: direction of the total force; we
      do not record forces) and ``destination`` the position (we do not record destinations).
    - ``episode.csv``: ``time, episode``.
    - ``start_goal.csv``: ``episode, start, goal`` (one row, ``[x, y, theta]`` lists).
    - ``scan.csv``: ``time, data`` (ranges rounded to 3, NaN → ``scan_range_max``), only when
      ``scan`` (``(T, beams)`` m, e.g. :attr:`Recorder.scans`) is given.

    ``time`` is ``round(seconds × 1e10)`` as an integer: Arena writes ``secs × 10e9 + nsecs``
    (10e9 is 1e10, a quirk in its recorder) and its metrics divide by 1e10, so this gives our
    seconds back there. ``record_period`` (s) down-samples like Arena's recorder
    (:data:`ARENA_RECORD_PERIOD` = 0.4 s is its ``record_frequency``); ``None`` writes every row.

    Returns:
        name (``odom``, ``cmd_vel``, ...) → path written.
    """
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    r = record
    rows = _sample_rows(r.time, record_period)
    stamps = [round(float(r.time[j]) * ARENA_TIME_SCALE) for j in rows]
    files: dict[str, Path] = {}

    def write(name: str, header: list[str], body: list[list[Any]]) -> None:
        path = out / f"{name}.csv"
        with path.open("w", newline="") as f:
            w = csv.writer(f)
            w.writerow(header)
            w.writerows(body)
        files[name] = path

    odom = []
    for s, j in zip(stamps, rows, strict=True):
        data = {
            "position": [_r3(v) for v in r.pose[j]],
            "velocity": [_r3(v) for v in r.velocity[j]],
        }
        odom.append([s, json.dumps(data)])
    write("odom", ["time", "data"], odom)
    write("cmd_vel", ["time", "data"],
          [[s, json.dumps([_r3(v) for v in r.command[j]])] for s, j in zip(stamps, rows,
                                                                             strict=True)])
    order = np.argsort(r.ped_row, kind="stable")
    sorted_rows = r.ped_row[order]
    starts = np.searchsorted(sorted_rows, rows, side="left")
    ends = np.searchsorted(sorted_rows, rows, side="right")
    peds = []
    for s, a, b in zip(stamps, starts, ends, strict=True):
        idx = order[a:b]
        agents = [
            {
                "id": str(int(r.ped_id[i])),
                "type": int(r.ped_kind[i]),
                "social_state": int(r.ped_state[i]),
                "position": [_r3(v) for v in r.ped_position[i]],
                "theta": _r3(r.ped_heading[i]),
                "destination": [_r3(v) for v in r.ped_position[i]],
            }
            for i in idx
        ]
        peds.append([s, json.dumps(agents)])
    write("pedsim_agents_data", ["time", "data"], peds)
    write("episode", ["time", "episode"], [[s, r.meta.episode] for s in stamps])
    write("start_goal", ["episode", "start", "goal"], [[
        r.meta.episode,
        json.dumps([_r3(v) for v in r.meta.start]),
        json.dumps([_r3(v) for v in r.meta.goal]),
    ]])
    if scan is not None:
        sc = np.asarray(scan, dtype=np.float64)
        if sc.shape[0] != r.steps:
            raise ValueError(f"scan has {sc.shape[0]} rows, the record {r.steps}")
        fill = scan_range_max if scan_range_max is not None else math.inf
        body = []
        for s, j in zip(stamps, rows, strict=True):
            ranges = np.where(np.isnan(sc[j]), fill, sc[j])
            body.append([s, json.dumps([_r3(v) for v in ranges])])
        write("scan", ["time", "data"], body)
    return files
