"""The web app's view of a run store: the run folders under one root folder, read safely.

A run is a folder directly under the root: an ``arena bench`` run (``run.json``), an ``arena
run`` run (``config.yaml`` and ``episode_*`` folders), or a job the web app started that has no
results yet (``job.json``, :mod:`arena.web.jobs`). Its name is its folder name. Every path a
request names is checked here: run names are one plain folder name, file paths stay inside
their run (no ``..``, no absolute path, no symlink out), so the app serves nothing but the
store's files.
"""

from __future__ import annotations

import contextlib
import csv
import json
import os
import re
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from arena.eval.live_bench import LIVE_DIR
from arena.live.server import LIVE_FILE

#: A run name: one folder name of plain characters.
RUN_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]{0,127}$")


class NotFound(LookupError):
    """A run or file the store does not have (or may not serve); the message says which."""


@dataclass(frozen=True)
class RunInfo:
    """One run of the store.

    Attributes:
        name: folder name (the run's id in URLs).
        kind: ``"bench"`` or ``"run"``.
        episodes: committed episodes.
        live: a live channel is open (its process runs).
        modified: s since the epoch, the folder's newest change.
        title: suite and contest (bench) or the run's config name.
    """

    name: str
    kind: str
    episodes: int
    live: bool
    modified: float
    title: str

    def as_json(self) -> dict[str, Any]:
        """The fields as a dict (the API's answer)."""
        return asdict(self)


def pid_alive(pid: int) -> bool:
    """Whether process ``pid`` exists."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


class RunStore:
    """The runs under ``root`` (see the module doc)."""

    def __init__(self, root: str | Path) -> None:
        self.root = Path(root).resolve()

    # -- paths ------------------------------------------------------------------------------------
    def folder(self, name: str) -> Path:
        """The run folder ``name``.

        Raises:
            NotFound: a name that is no plain folder name, or no run of that name.
        """
        if not RUN_NAME.match(name or ""):
            raise NotFound(f"no run named {name!r}")
        path = (self.root / name).resolve()
        if path.parent != self.root or not self.kind(path):
            raise NotFound(f"no run named {name!r}")
        return path

    def file(self, name: str, rel: str) -> Path:
        """The file ``rel`` (a path relative to the run folder) of run ``name``.

        Raises:
            NotFound: an absolute path, a path with ``..``, one that leaves the run (a symlink),
                or no such file.
        """
        folder = self.folder(name)
        parts = Path(rel).parts
        if not rel or Path(rel).is_absolute() or ".." in parts or "\\" in rel:
            raise NotFound(f"no file {rel!r} in run {name!r}")
        path = (folder / rel).resolve()
        if not path.is_relative_to(folder) or not path.is_file():
            raise NotFound(f"no file {rel!r} in run {name!r}")
        return path

    @staticmethod
    def kind(path: Path) -> str | None:
        """``"bench"``, ``"run"`` or ``None`` for a folder that is no run."""
        if (path / "run.json").is_file():
            return "bench"
        if (path / "config.yaml").is_file() and (
                any(path.glob("episode_*")) or (path / LIVE_FILE).is_file()):
            return "run"
        kind = _json(path / "job.json").get("kind")  # a job that has written nothing yet
        return kind if kind in ("bench", "run") else None

    # -- reading ----------------------------------------------------------------------------------
    def runs(self) -> list[RunInfo]:
        """Every run, newest first."""
        if not self.root.is_dir():
            return []
        out = []
        for path in self.root.iterdir():
            if path.is_dir() and RUN_NAME.match(path.name) and self.kind(path):
                out.append(self.info(path.name))
        return sorted(out, key=lambda r: -r.modified)

    def info(self, name: str) -> RunInfo:
        """What the run list shows of run ``name``."""
        folder = self.folder(name)
        kind = self.kind(folder)
        assert kind is not None
        if kind == "bench":
            manifest = _json(folder / "run.json")
            title = " × ".join(Path(str(manifest.get(k, "?"))).stem for k in ("suite", "contest"))
            if not manifest:  # a job that has not written its manifest yet
                title = str(_json(folder / "job.json").get("title", title))
            episodes = sum(1 for _ in folder.glob("episodes/*/*/*.json"))
        else:
            title = folder.name
            episodes = sum(1 for _ in folder.glob("episode_*/episode.json"))
        stamps = [p.stat().st_mtime for p in (folder, *folder.iterdir())]
        return RunInfo(name=folder.name, kind=kind, episodes=episodes,
                       live=self.live(name) is not None, modified=max(stamps), title=title)

    def channels(self, name: str) -> dict[str, dict[str, Any]]:
        """The run's open live channels by name, each ``{host, port, token, pid}``.

        An ``arena run`` has one, ``live`` (its ``live.json``); an ``arena bench --live`` one per
        worker (``live/worker_<pid>.json``, :mod:`arena.eval.live_bench`). A channel whose
        process is gone is left out.
        """
        folder = self.folder(name)
        files = [(folder / LIVE_FILE, "live"),
                 *((p, p.stem) for p in sorted((folder / LIVE_DIR).glob("worker_*.json")))]
        out = {}
        for path, channel in files:
            if not path.is_file():
                continue
            info = _json(path)
            if isinstance(info.get("pid"), int) and pid_alive(info["pid"]) and \
                    isinstance(info.get("port"), int):
                out[channel] = info
        return out

    def live(self, name: str, channel: str | None = None) -> dict[str, Any] | None:
        """One open live channel of run ``name`` (``None``: its first), or ``None``."""
        channels = self.channels(name)
        if channel is None:
            return next(iter(channels.values()), None)
        return channels.get(channel)

    def results(self, name: str) -> list[dict[str, Any]]:
        """One row per finished episode: its figures and metrics.

        Each row's ``record`` is the path of its record in the run ("" if none).
        """
        folder = self.folder(name)
        if self.kind(folder) == "bench":
            from arena.eval.store import load_rows

            return load_rows(folder)
        summary = folder / "summary.csv"
        if not summary.is_file():
            return []
        with summary.open(newline="") as f:
            rows: list[dict[str, Any]] = [dict(r) for r in csv.DictReader(f)]
        for row in rows:
            for key, value in row.items():
                with contextlib.suppress(ValueError):
                    row[key] = float(value) if key not in ("map", "robot", "stage") else value
            rec = Path(f"episode_{int(row.get('index') or 0):03d}") / "episode.parquet"
            row["record"] = rec.as_posix() if (folder / rec).is_file() else ""
        return rows

    def records(self, name: str) -> list[str]:
        """The run's episode records, as paths relative to the run folder."""
        folder = self.folder(name)
        found = [*folder.glob("episodes/*/*/*.parquet"), *folder.glob("episode_*/episode.parquet")]
        return sorted(p.relative_to(folder).as_posix() for p in found
                      if not p.name.startswith("."))


def _json(path: Path) -> dict[str, Any]:
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}
