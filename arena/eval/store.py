"""A benchmark run's results store: one committed file pair per finished episode.

Layout of a run folder::

    run.json                                        the run manifest (suite, contest, seed, ...)
    episodes/<contestant>/<stage>/<episode>.parquet the EpisodeRecord (arena.eval.io.load_record)
    episodes/<contestant>/<stage>/<episode>.json    the metrics row, written last

Every file is written to a temporary file in the same folder and moved into place with
:func:`os.replace`, so a reader never sees a half-written file. The ``.json`` row is written
after the record: its presence marks the episode as committed (:func:`completed`). A run killed
at any moment therefore leaves only whole, committed episodes plus, at worst, an orphaned record
or a temporary file, which a resumed run overwrites.
"""

from __future__ import annotations

import json
import math
import os
import tempfile
from collections.abc import Iterable, Mapping
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import pyarrow as pa
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    StrictFloat,
    StrictInt,
    StrictStr,
    ValidationError,
)

from arena import __version__
from arena.core.errors import ArenaError, ConfigError, from_validation_error
from arena.core.names import check_name
from arena.eval.io import save_record
from arena.eval.record import EpisodeRecord

MANIFEST = "run.json"
EPISODES = "episodes"
#: Manifest keys a resumed run must match.
MANIFEST_KEYS = ("suite", "contest", "seed", "scale", "worlds", "simulator")

#: What a manifest written before a key existed means by its absence.
MANIFEST_DEFAULTS: dict[str, Any] = {"simulator": "native2d"}

#: Columns of :func:`load_results` before the metric columns, with their types.
ID_COLUMNS: tuple[tuple[str, pa.DataType], ...] = (
    ("contestant", pa.string()),
    ("local_planner", pa.string()),
    ("inter_planner", pa.string()),
    ("stage", pa.string()),
    ("episode", pa.int64()),
    ("seed", pa.int64()),
    ("map", pa.string()),
    ("robot", pa.string()),
    ("outcome", pa.string()),
)
#: Columns of :func:`load_results` after the metric columns, with their types.
TAIL_COLUMNS: tuple[tuple[str, pa.DataType], ...] = (
    ("time", pa.float64()),
    ("path_length", pa.float64()),
    ("collisions", pa.int64()),
    ("wall_time", pa.float64()),
    ("error", pa.string()),
    ("record", pa.string()),
)


def _atomic_write(path: Path, write: Any) -> None:
    """Call ``write(tmp_path)`` on a temporary file next to ``path``, then move it into place."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    os.close(fd)
    try:
        write(Path(tmp))
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _write_json(path: Path, data: Any) -> None:
    def write(tmp: Path) -> None:
        with tmp.open("w") as f:
            json.dump(data, f, indent=1, allow_nan=True)
            f.flush()
            os.fsync(f.fileno())

    _atomic_write(path, write)


def episode_stem(run: Path, contestant: str, stage: str, episode: int) -> Path:
    """``<run>/episodes/<contestant>/<stage>/<episode:04d>`` (no suffix).

    Raises:
        ConfigError: a name that cannot be a folder name (:func:`arena.core.names.check_name`).
    """
    check_name(contestant, "contestant name")
    check_name(stage, "stage name")
    return Path(run) / EPISODES / contestant / stage / f"{int(episode):04d}"


# -- manifest ---------------------------------------------------------------------------------
def write_manifest(
    run: str | Path, *, suite: str, contest: str, seed: int, scale: float,
    worlds: str | None = None, simulator: str = "native2d",
) -> dict[str, Any]:
    """Write ``<run>/run.json`` for a new run and return it.

    ``worlds``: the worlds folder; ``simulator``: the ``sim.backend.type`` of every episode.
    """
    data: dict[str, Any] = {
        "suite": str(suite),
        "contest": str(contest),
        "seed": int(seed),
        "scale": float(scale),
        "worlds": None if worlds is None else str(worlds),
        "simulator": str(simulator),
        "created": datetime.now(UTC).isoformat(timespec="seconds"),
        "arena_version": __version__,
    }
    _write_json(Path(run) / MANIFEST, data)
    return data


class RunManifest(BaseModel):
    """The fields of ``run.json`` a run needs, checked when it is read (other keys pass)."""

    model_config = ConfigDict(extra="allow", allow_inf_nan=False)

    suite: StrictStr = Field(min_length=1)
    contest: StrictStr = Field(min_length=1)
    seed: StrictInt = Field(ge=0)
    scale: StrictFloat = Field(gt=0)
    worlds: StrictStr | None = Field(None, min_length=1)
    simulator: StrictStr = Field(MANIFEST_DEFAULTS["simulator"], min_length=1)


def read_manifest(run: str | Path) -> dict[str, Any]:
    """Read ``<run>/run.json`` and check its :class:`RunManifest` fields.

    Raises:
        ArenaError: no manifest (not a run folder), an unreadable one, or a bad field
            (:class:`~arena.core.errors.ConfigError` naming the file and the field).
    """
    path = Path(run) / MANIFEST
    if not path.is_file():
        raise ArenaError(f"{path}: no run manifest; {run} is not a benchmark run folder")
    try:
        data = json.loads(path.read_bytes())
    except (OSError, ValueError, RecursionError) as e:  # ValueError: bad JSON or UTF-8
        raise ArenaError(f"{path}: unreadable run manifest ({e})") from None
    if not isinstance(data, dict):
        raise ConfigError(f"the run manifest is not a JSON object (got {type(data).__name__})",
                          source=str(path))
    try:
        RunManifest.model_validate(data)
    except ValidationError as e:
        raise from_validation_error(e, source=str(path)) from None
    return data


def check_manifest(run: str | Path, expected: Mapping[str, Any]) -> dict[str, Any]:
    """Check that a run folder's manifest matches ``expected`` on :data:`MANIFEST_KEYS`.

    Raises:
        ArenaError: naming the manifest file and the first field that differs.
    """
    data = read_manifest(run)
    path = Path(run) / MANIFEST
    for key in MANIFEST_KEYS:
        if key not in expected:
            continue
        have, want = data.get(key, MANIFEST_DEFAULTS.get(key)), expected[key]
        same = (
            math.isclose(float(have), float(want))
            if key == "scale" and isinstance(have, int | float)
            else have == want
        )
        if not same:
            raise ArenaError(
                f"{path}: cannot resume: field {key!r} of the run is {have!r}, "
                f"this call asks for {want!r}"
            )
    return data


# -- episodes ---------------------------------------------------------------------------------
def commit_episode(
    run: str | Path,
    row: Mapping[str, Any],
    record: EpisodeRecord | None,
) -> Path:
    """Commit one finished episode: its record (if any), then its metrics row (last).

    ``row`` holds the :func:`load_results` fields (``contestant``, ``stage``, ``episode`` ...)
    and the metrics; ``record`` is filled in from where the record lands. Returns the row file.
    """
    run = Path(run)
    stem = episode_stem(run, str(row["contestant"]), str(row["stage"]), int(row["episode"]))
    data = dict(row)
    data["record"] = ""
    if record is not None:
        target = stem.with_suffix(".parquet")
        _atomic_write(target, lambda tmp: save_record(record, tmp))
        data["record"] = target.relative_to(run).as_posix()
    target = stem.with_suffix(".json")
    _write_json(target, data)
    return target


def _row_files(run: Path) -> Iterable[Path]:
    root = run / EPISODES
    if not root.is_dir():
        return []
    return (p for p in root.glob("*/*/*.json") if not p.name.startswith("."))


def completed(run: str | Path) -> set[tuple[str, str, int]]:
    """``(contestant, stage, episode)`` of every committed episode of a run."""
    out = set()
    for p in _row_files(Path(run)):
        try:
            episode = int(p.stem)
        except ValueError:
            continue
        out.add((p.parent.parent.name, p.parent.name, episode))
    return out


def _check_row(run: Path, path: Path, row: Any) -> dict[str, Any]:
    """``row`` if it is a metrics row as :func:`commit_episode` writes it, else a one-line error.

    Every fixed column must have its type (``seed`` may be null) and every other value must be a
    number or null; ``contestant``, ``stage`` and ``episode`` must match the file's place. Its
    names become paths in reports: a tampered or foreign run folder must not name ``../../X``,
    so they must be safe names, and ``record`` the parquet file beside the row.
    """
    redo = "; delete the file to run that episode again (--resume)"
    if not isinstance(row, dict):
        raise ArenaError(f"{path}: expected an episode row (a JSON object), "
                         f"got {type(row).__name__}{redo}")
    for name, typ in (*ID_COLUMNS, *TAIL_COLUMNS):
        value = row.get(name)
        if value is None and name in ("seed", "record"):
            continue
        if pa.types.is_string(typ):
            ok = isinstance(value, str)
        elif pa.types.is_integer(typ):
            ok = isinstance(value, int) and not isinstance(value, bool)
        else:
            ok = isinstance(value, int | float) and not isinstance(value, bool)
        if not ok:
            raise ArenaError(f"{path}: field {name!r}: expected {typ}, got {value!r}{redo}")
    for name, value in row.items():
        if name not in _FIXED and not (
            value is None or (isinstance(value, int | float) and not isinstance(value, bool))
        ):
            raise ArenaError(f"{path}: metric {name!r}: expected a number or null, "
                             f"got {value!r}{redo}")
    for key in ("contestant", "stage"):  # these become paths in reports
        try:
            check_name(row[key], f"{key} name", source=str(path), path=key)
        except ConfigError as e:
            raise ArenaError(f"{e}{redo}") from None
    place = (path.parent.parent.name, path.parent.name, path.stem)
    if (row["contestant"], row["stage"], f"{row['episode']:04d}") != place:
        raise ArenaError(f"{path}: the row is of {row['contestant']}/{row['stage']}/"
                         f"{row['episode']}, not of the episode its file name says{redo}")
    record = row.get("record") or ""
    if record and record != path.with_suffix(".parquet").relative_to(run).as_posix():
        raise ConfigError(f"{record!r} is not this episode's record file", source=str(path),
                          path="record")
    return row


def load_rows(run: str | Path) -> list[dict[str, Any]]:
    """Every committed metrics row, sorted by (contestant, stage, episode).

    Raises:
        ArenaError: an unreadable or malformed row file (naming it).
    """
    rows = []
    for p in _row_files(Path(run)):
        try:
            data = json.loads(p.read_bytes())
        except (OSError, ValueError, RecursionError) as e:
            raise ArenaError(f"{p}: unreadable episode row ({e}); delete the file to run that "
                             f"episode again (--resume)") from None
        rows.append(_check_row(Path(run), p, data))
    rows.sort(key=lambda r: (str(r["contestant"]), str(r["stage"]), int(r["episode"])))
    return rows


_FIXED = frozenset(n for n, _ in (*ID_COLUMNS, *TAIL_COLUMNS))


def metric_columns(rows: Iterable[Mapping[str, Any]]) -> list[str]:
    """The metric names found in ``rows`` (every key that is no fixed column), sorted."""
    return sorted({k for r in rows for k in r if k not in _FIXED})


def load_results(run: str | Path) -> pa.Table:
    """One row per committed episode: ids, outcome, every metric (float64), figures.

    Columns: ``contestant, local_planner, inter_planner, stage, episode, seed, map, robot,
    outcome``, the metrics (sorted by name), ``time, path_length, collisions, wall_time, error,
    record`` (the record's path relative to the run folder; empty when the episode has none).
    Rows are sorted by (contestant, stage, episode). A metric named like a fixed column
    (``path_length``, ``collisions``) appears once, as the fixed column with its type.
    """
    rows = load_rows(run)
    metrics = metric_columns(rows)
    columns: dict[str, pa.Array] = {}
    fields = []
    for name, typ in ID_COLUMNS:
        fields.append(pa.field(name, typ))
        columns[name] = pa.array([r.get(name) for r in rows], type=typ)
    for name in metrics:
        fields.append(pa.field(name, pa.float64()))
        vals = [r.get(name) for r in rows]
        columns[name] = pa.array(
            [math.nan if v is None else float(v) for v in vals], type=pa.float64()
        )
    for name, typ in TAIL_COLUMNS:
        fields.append(pa.field(name, typ))
        columns[name] = pa.array([r.get(name) for r in rows], type=typ)
    schema = pa.schema(fields)
    return pa.table([columns[f.name] for f in schema], schema=schema)


def summarize(table: pa.Table) -> list[dict[str, Any]]:
    """Per (contestant, stage), in table order: episodes, success rate, collisions, mean time.

    ``collisions`` is the mean number of collision events per episode; ``time`` the mean episode
    time over all episodes (s).
    """
    groups: dict[tuple[str, str], list[dict[str, Any]]] = {}
    for r in table.select(["contestant", "stage", "outcome", "collisions", "time"]).to_pylist():
        groups.setdefault((r["contestant"], r["stage"]), []).append(r)
    out = []
    for (contestant, stage), rs in groups.items():
        n = len(rs)
        times = [float(r["time"]) for r in rs if r["time"] is not None]
        out.append(
            {
                "contestant": contestant,
                "stage": stage,
                "episodes": n,
                "success_rate": sum(r["outcome"] == "success" for r in rs) / n,
                "collisions": sum(int(r["collisions"] or 0) for r in rs) / n,
                "time": sum(times) / len(times) if times else math.nan,
                "errors": sum(r["outcome"] == "error" for r in rs),
            }
        )
    return out
