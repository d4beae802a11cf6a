"""Collect every simulation step of one episode into an :class:`~arena.eval.record.EpisodeRecord`.

The :class:`Recorder` keeps robot 0 (one row per recorded state) and every pedestrian (whole
arrays appended per step, long format) in growing numpy buffers: capacity doubles when full, so
recording is amortised O(1) per step with no per-agent Python loop. Events (goal reached, new
goal, teleport, outcome) are kept as ``(time s, kind, detail)`` tuples.

It is the one recorder of an episode: a hook of :class:`~arena.episode.runner.EpisodeRunner`
(it records the state after the reset and after every step, and takes the runner's events at
the episode's end), whose record the metrics read and which also writes the episode's
``trajectory.csv`` and ``agents.csv`` (:meth:`Recorder.write_csv`).
"""

from __future__ import annotations

import csv
import dataclasses
import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from arena.episode.runner import EpisodeHooks, EpisodeRunner
from arena.eval.record import EpisodeMeta, EpisodeRecord, PerceptionRecord
from arena.scene.state import SimState

if TYPE_CHECKING:
    from arena.perception.stage import Perceived

FloatArray = NDArray[np.float64]

# Robot buffer columns: time, x, y, theta, vx, vy, omega, cmd_vx, cmd_vy, cmd_omega, min_range.
_ROBOT_F = 11
# Pedestrian float columns: x, y, vx, vy, heading, radius.
_PED_F = 6
# Pedestrian int columns: row, id, kind, state.
_PED_I = 4


ROBOT_COLUMNS = (
    "step", "time", "x", "y", "theta", "vx", "vy", "omega", "cmd_vx", "cmd_vy", "cmd_omega",
    "min_range", "collision",
)
"""Columns of ``trajectory.csv``."""
AGENT_COLUMNS = (
    "step", "time", "id", "x", "y", "vx", "vy", "heading", "radius", "kind", "state",
)
"""Columns of ``agents.csv``."""


def _write_csv(
    path: Path, header: tuple[str, ...], rows: np.ndarray, int_cols: tuple[int, ...]
) -> None:
    with path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        for row in rows:
            w.writerow([int(v) if i in int_cols else f"{v:.6g}" for i, v in enumerate(row)])


def _grow(buf: np.ndarray, need: int) -> np.ndarray:
    """``buf`` with at least ``need`` rows (capacity doubled), old rows kept."""
    if need <= buf.shape[0]:
        return buf
    cap = max(need, 2 * buf.shape[0], 16)
    out = np.empty((cap, *buf.shape[1:]), dtype=buf.dtype)
    out[: buf.shape[0]] = buf
    return out


class Recorder(EpisodeHooks):
    """Records robot 0 and all pedestrians at every simulation step.

    Call :meth:`record` with the state after ``reset`` and after every ``step`` (and, if wanted,
    after a teleport), :meth:`event` for discrete happenings, and :meth:`finish` once at the end.

    Args:
        keep_scans: also keep robot 0's laser scan of every row (``scans``: ``(T, beams)`` m),
            e.g. for :func:`arena.eval.io.export_arena_csv`'s ``scan.csv``. It is robot 0's
            primary lidar (``RobotStates.scans``: the sensor named ``laser``); to record another
            sensor, read ``state.robots.sensors[0][name]`` in an ``after_step`` hook.
        capacity: initial number of robot rows reserved.
    """

    def __init__(self, *, keep_scans: bool = False, capacity: int = 256) -> None:
        self.keep_scans = keep_scans
        self._n = 0
        self._k = 0
        self._robot = np.empty((capacity, _ROBOT_F), dtype=np.float64)
        # wall, obstacle, pedestrian, robot contact; no laser beams (min_range undefined)
        self._coll = np.empty((capacity, 5), dtype=np.bool_)
        self._step = np.empty(capacity, dtype=np.int64)
        self._ped_f = np.empty((capacity * 4, _PED_F), dtype=np.float64)
        self._ped_i = np.empty((capacity * 4, _PED_I), dtype=np.int64)
        self._scans: np.ndarray | None = None
        self.events: list[tuple[float, str, str]] = []

    def __len__(self) -> int:
        """Number of robot rows recorded so far."""
        return self._n

    def record(self, state: SimState, command: FloatArray | None = None) -> None:
        """Append robot 0 and every pedestrian of ``state``.

        Args:
            state: the snapshot.
            command: ``(3,)`` ``[vx m/s, vy m/s, omega rad/s]`` applied during the step that led
                to ``state``; default ``state.robots.commands[0]`` (what the backend received).
        """
        r = state.robots
        n = self._n
        self._robot = _grow(self._robot, n + 1)
        self._coll = _grow(self._coll, n + 1)
        self._step = _grow(self._step, n + 1)
        self._step[n] = state.step
        scan = r.scans[0]
        min_range = float(scan.min()) if scan.size else math.inf
        cmd = r.commands[0] if command is None else np.asarray(command, dtype=np.float64)
        row = self._robot[n]
        row[0] = state.time
        row[1:4] = r.poses[0]
        row[4:7] = r.twists[0]
        row[7:10] = cmd
        row[10] = min_range
        c = state.collisions
        self._coll[n] = (
            bool(c.wall[0]), c.obstacle[0] >= 0, c.agent[0] >= 0, c.robot[0] >= 0, not scan.size
        )
        if self.keep_scans:
            if self._scans is None:
                self._scans = np.empty((self._robot.shape[0], scan.size), dtype=np.float64)
            self._scans = _grow(self._scans, n + 1)
            self._scans[n] = scan
        a = state.agents
        m = len(a)
        if m:
            k = self._k
            self._ped_f = _grow(self._ped_f, k + m)
            self._ped_i = _grow(self._ped_i, k + m)
            f = self._ped_f[k : k + m]
            f[:, 0:2] = a.positions
            f[:, 2:4] = a.velocities
            f[:, 4] = a.headings
            f[:, 5] = a.radii
            i = self._ped_i[k : k + m]
            i[:, 0] = n
            i[:, 1] = a.ids
            i[:, 2] = a.kinds
            i[:, 3] = a.states
            self._k = k + m
        self._n = n + 1

    # -- as a hook of the episode runner -------------------------------------------------------
    def initialize_episode(self, runner: EpisodeRunner) -> None:
        """Record the state after the reset."""
        assert runner.state is not None
        self.record(runner.state)

    def after_step(self, runner: EpisodeRunner) -> None:
        """Record the state after the step."""
        assert runner.state is not None
        self.record(runner.state)

    def episode_end(self, runner: EpisodeRunner) -> None:
        """Take the episode's events (the runner's, in order)."""
        self.events.extend(runner.events)

    def event(self, time: float, kind: str, detail: str = "") -> None:
        """Note a discrete event at ``time`` (s).

        Kinds used by :func:`arena.eval.episodes.run_episode`: ``goal_reached``, ``new_goal``,
        ``teleport``, ``reset``, ``outcome`` (detail: the outcome value).
        """
        self.events.append((float(time), kind, detail))

    @property
    def poses(self) -> FloatArray:
        """``(T, 3)`` robot poses recorded so far (a copy)."""
        return self._robot[: self._n, 1:4].copy()

    @property
    def scans(self) -> FloatArray | None:
        """``(T, beams)`` robot 0's laser ranges (m), or ``None`` unless ``keep_scans``."""
        return None if self._scans is None else self._scans[: self._n].copy()

    def write_csv(self, folder: Path) -> dict[str, str]:
        """Write ``trajectory.csv`` (robot 0 per row) and ``agents.csv`` (long format).

        ``trajectory.csv``: ``step, time, x, y, theta, vx, vy, omega, cmd_vx, cmd_vy,
        cmd_omega, min_range, collision`` (``min_range`` NaN without beams, ``collision`` 0/1);
        ``agents.csv``: ``step, time, id, x, y, vx, vy, heading, radius, kind, state``. Floats
        with 6 significant digits. Returns ``{"trajectory": path, "agents": path}``.
        """
        n, k = self._n, self._k
        rb, co = self._robot[:n], self._coll[:n]
        robot = np.column_stack([
            self._step[:n], rb[:, :10], np.where(co[:, 4], math.nan, rb[:, 10]),
            co[:, :4].any(axis=1),
        ])
        traj = folder / "trajectory.csv"
        _write_csv(traj, ROBOT_COLUMNS, robot, int_cols=(0, 12))
        pi, pf = self._ped_i[:k], self._ped_f[:k]
        rows = pi[:, 0]
        agents_rows = np.column_stack([
            self._step[rows], rb[rows, 0], pi[:, 1], pf[:, 0:5], pf[:, 5], pi[:, 2], pi[:, 3],
        ]) if k else np.zeros((0, 11))
        agents = folder / "agents.csv"
        _write_csv(agents, AGENT_COLUMNS, agents_rows, int_cols=(0, 2, 9, 10))
        return {"trajectory": str(traj), "agents": str(agents)}

    def finish(self, meta: EpisodeMeta) -> EpisodeRecord:
        """The record of everything recorded so far (arrays are copies)."""
        n, k = self._n, self._k
        rb = self._robot[:n]
        co = self._coll[:n]
        pf = self._ped_f[:k]
        pi = self._ped_i[:k]
        return EpisodeRecord(
            meta=meta,
            time=rb[:, 0].copy(),
            pose=rb[:, 1:4].copy(),
            velocity=rb[:, 4:7].copy(),
            command=rb[:, 7:10].copy(),
            min_range=rb[:, 10].copy(),
            collision_wall=co[:, 0].copy(),
            collision_obstacle=co[:, 1].copy(),
            collision_pedestrian=co[:, 2].copy(),
            collision_robot=co[:, 3].copy(),
            ped_row=pi[:, 0].copy(),
            ped_id=pi[:, 1].copy(),
            ped_kind=pi[:, 2].copy(),
            ped_state=pi[:, 3].copy(),
            ped_position=pf[:, 0:2].copy(),
            ped_velocity=pf[:, 2:4].copy(),
            ped_heading=pf[:, 4].copy(),
            ped_radius=pf[:, 5].copy(),
            events=list(self.events),
        )


def with_perception(
    record: EpisodeRecord, log: Sequence[tuple[float, Perceived]]
) -> EpisodeRecord:
    """``record`` with what a detecting perception plugin saw; ``record`` itself without it.

    ``log`` holds ``(time s, Perceived)`` of each control tick
    (:attr:`~arena.episode.navigation.NavigationController.perceived`).

    A tick belongs to the robot row of the same time (the state it perceived); its ``seen``
    flags follow that row's pedestrians in their recorded order.
    """
    if not log:
        return record
    t, k = record.steps, record.ped_row.shape[0]
    perceived = np.zeros(t, dtype=bool)
    seen = np.zeros(k, dtype=bool)
    starts = np.searchsorted(record.ped_row, np.arange(t + 1))  # ped rows grouped by row
    trk: list[tuple[int, NDArray[np.int64], NDArray[np.float64]]] = []
    det: list[tuple[int, NDArray[np.float64]]] = []
    for time, p in log:
        row = int(np.searchsorted(record.time, time - 1e-9))
        if row >= t or abs(record.time[row] - time) > 1e-6:
            continue  # a tick without a recorded state (none in a normal episode)
        perceived[row] = True
        a, b = starts[row], starts[row + 1]
        m = min(b - a, p.seen.shape[0])
        seen[a : a + m] = p.seen[:m]
        trk.append((row, p.tracks.ids, p.tracks.positions))
        det.append((row, p.detections))
    trk_row = np.concatenate([np.full(len(ids), r, dtype=np.int64) for r, ids, _ in trk])
    det_row = np.concatenate([np.full(len(xy), r, dtype=np.int64) for r, xy in det])
    return dataclasses.replace(record, perception=PerceptionRecord(
        perceived=perceived, seen=seen, trk_row=trk_row,
        trk_id=np.concatenate([ids for _, ids, _ in trk]).astype(np.int64),
        trk_position=np.concatenate([xy for *_, xy in trk]).reshape(-1, 2),
        det_row=det_row, det_position=np.concatenate([xy for _, xy in det]).reshape(-1, 2),
    ))
