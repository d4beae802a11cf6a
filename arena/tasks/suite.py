"""Benchmark suites and contests (Arena specs §2.9), loaded unchanged from Arena's files.

``arena_bringup/configs/benchmark/``:

* ``suites/<name>.yaml``: ``stages: [{name, episodes, robot, map, tm_robots, tm_obstacles,
  config: {<task_generator.yaml overlay>}, seed?, timeout?}]``.
* ``contests/<name>.yaml``: ``contestants: [{name, local_planner, inter_planner: bypass}]``.
* ``config.yaml``: ``suite: {config, scale_episodes: 1}``, ``contest: {config}``,
  ``general: {simulator}``.

Arena's ``config`` overlay maps onto our ``task`` block: ``RANDOM.{static,interactive}.{min,max,
models}`` → ``obstacles.random`` counts and models, ``RANDOM.dynamic.{min,max}`` → pedestrian
counts, ``SCENARIO.file`` → the scenario file (relative to the stage world's ``scenarios/``
folder, Arena's ``worlds/<map>/scenarios/``), ``timeout`` and ``goal_radius`` → the same keys.
``RANDOM.dynamic.models`` names Arena's pedestrian actor models (``actor1``): our pedestrians
are simulated bodies with no mesh, so the names are accepted and ignored. ``RANDOM.seed``
replaces the stage seed (Arena applies the stage's ``config`` after the stage seed).

Our native additions per stage: ``map`` may be a packaged world name, a world folder (a path
with ``/``, relative to the suite file), Arena's ``dynamic_map`` (the run's generated map) or a
map block (``{type: canteen, ...}``); ``task:`` is an overlay in our
:class:`~arena.tasks.config.TaskConfig` format merged last; ``map_per_episode`` (default true)
gives a generated map a new instance every episode.

World names (``map: arena_hospital_small``, Arena's folder names) are looked up in a *worlds
folder* first (``arena bench --worlds DIR``, ``suite.worlds`` of a benchmark ``config.yaml`` or
the suite's own ``worlds:`` key): see :mod:`arena.tasks.suite_worlds`. A stage's
``SCENARIO.file`` is then read from ``<world folder>/scenarios/`` (then next to the suite).

A stage's seed defaults to Arena's: the last 4 bytes of the SHA-1 of the stage's canonical JSON
(sorted keys), as a non-negative int32. The episodes of a stage are drawn from
:func:`stage_run_seed` of the run seed and the stage seed, with episode numbers local to the
stage, so episode k of a stage is the same whatever comes before it.
"""

from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, StrictInt, ValidationError, field_validator

from arena.config.loader import merge, validate_plugins
from arena.config.schema import ExperimentConfig
from arena.core.errors import ConfigError, from_validation_error
from arena.core.names import RULE, SafeName
from arena.core.rng import MAX_SEED, Seed, child_seed
from arena.maps.sources import MAP_SOURCES, check_worlds_folder, resolve_world
from arena.nav.global_planners.base import GLOBAL_PLANNERS
from arena.nav.local_planners.base import LOCAL_PLANNERS
from arena.perception.stage import PERCEPTION
from arena.tasks.datafiles import find_data_file, read_arena_yaml
from arena.tasks.suite_worlds import find_stage_world

MAX_EPISODES = 1_000_000
"""Most episodes a (scaled) suite may have: weeks of simulation; more is a typo in a scale."""


class _Arena(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid")


class RandomClass(_Arena):
    """Arena's ``RANDOM.<class>``: count range and model names."""

    min: int | None = Field(None, ge=0, description="fewest of this class")
    max: int | None = Field(None, ge=0, description="most of this class")
    models: list[str] | None = Field(None, description="model names (Arena: list or 'a;b')")

    @field_validator("models", mode="before")
    @classmethod
    def _split(cls, v: Any) -> Any:
        if isinstance(v, str):  # dynamic_reconfigure's ";"-separated string
            return [s.strip() for s in v.split(";") if s.strip()]
        return v


class RandomBlock(_Arena):
    """Arena's ``RANDOM`` block."""

    seed: StrictInt | None = Field(
        None, ge=-1, le=MAX_SEED, description="replaces the stage seed when >= 0 (-1: unset)"
    )
    static: RandomClass | None = None
    interactive: RandomClass | None = None
    dynamic: RandomClass | None = None


class FileBlock(_Arena):
    """Arena's ``SCENARIO`` / ``PARAMETRIZED`` block."""

    file: str = Field(description="file name")


class StagedBlock(_Arena):
    """Arena's ``STAGED`` block."""

    curriculum: str = "default"
    index: int = Field(0, ge=0)


class ZonesBlock(_Arena):
    """Arena's ``ZONES`` block."""

    file: str | None = None
    scenario: str | None = None


class TaskOverlay(_Arena):
    """A stage's ``config``: a partial Arena ``task_generator.yaml``."""

    RANDOM: RandomBlock | None = None
    SCENARIO: FileBlock | None = None
    PARAMETRIZED: FileBlock | None = None
    STAGED: StagedBlock | None = None
    ZONES: ZonesBlock | None = None
    timeout: float | None = Field(None, description="s per episode")
    goal_radius: float | None = Field(None, gt=0, description="m")
    goal_tolerance_angle: float | None = Field(None, gt=0, description="rad")
    episodes: int | None = Field(None, description="Arena's desired resets; the stage decides")


class SuiteStage(_Arena):
    """One stage of a suite."""

    name: SafeName = Field(description=f"stage name (reports, output folders): {RULE}")
    episodes: int = Field(
        ge=0, le=MAX_EPISODES, description="episodes before scale_episodes (<= 1,000,000)"
    )
    robot: str | None = Field(None, description="robot preset or YAML; None: the run's")
    map: str | dict[str, Any] | None = Field(
        None, description="world name/folder, 'dynamic_map' or a map block; None: the run's"
    )
    tm_robots: str = Field("random", description="robot task mode")
    tm_obstacles: str = Field("random", description="obstacle task mode")
    config: TaskOverlay = Field(default_factory=TaskOverlay, description="Arena overlay")
    task: dict[str, Any] | None = Field(None, description="overlay in our task format")
    seed: Seed | None = Field(None, description="stage seed; default from SHA-1")
    timeout: float | None = Field(None, gt=0, description="s per episode; default: the run's")
    map_per_episode: bool = Field(
        True, description="a generated map gets a new instance every episode"
    )


def _unique_names(items: list[Any], what: str) -> list[Any]:
    """Refuse two entries with one name: they would share one results folder."""
    seen: dict[str, int] = {}
    for i, item in enumerate(items):
        if item.name in seen:
            raise ValueError(
                f"[{seen[item.name]}] and [{i}] are both named {item.name!r}; {what} names must "
                "be unique (each names a results folder: two would mix their results)"
            )
        seen[item.name] = i
    return items


class SuiteFile(_Arena):
    """``suites/<name>.yaml``."""

    stages: list[SuiteStage] = Field(min_length=1, description="stages, unique names")
    worlds: str | None = Field(
        None, description="folder of worlds in Arena's layout (<world>/map/map.yaml) that "
        "world names are looked up in first, relative to this file (our addition; --worlds "
        "overrides it)",
    )

    @field_validator("stages")
    @classmethod
    def _unique(cls, v: list[SuiteStage]) -> list[SuiteStage]:
        return _unique_names(v, "stage")


class Contestant(_Arena):
    """One contestant: a navigation stack."""

    name: SafeName = Field(description=f"contestant name (reports, output folders): {RULE}")
    local_planner: str = Field(description="local planner name")
    inter_planner: str = Field("bypass", description="Arena's intermediate planner")
    params: dict[str, Any] = Field(
        default_factory=dict,
        description="local planner parameters (our addition to Arena's format), e.g. "
        "{weights: runs/x/policy.npz} for rosnav_rl",
    )
    perception: dict[str, Any] | None = Field(
        None, description="navigation.perception of this contestant (our addition), e.g. "
        "{type: lidar}; default: the run's (the ground truth)",
    )
    global_planner: str | dict[str, Any] | None = Field(
        None, description="navigation.global_planner of this contestant (our addition), a "
        "name or a block, e.g. artplanner; default: the run's (A*)",
    )
    navigation: dict[str, Any] = Field(
        default_factory=dict,
        description="other navigation settings of this contestant's stack (our addition), "
        "merged over the run's, e.g. {oscillation_timeout: 5.0} to turn recovery on",
    )


class ContestFile(_Arena):
    """``contests/<name>.yaml``."""

    contestants: list[Contestant] = Field(min_length=1, description="contestants, unique names")

    @field_validator("contestants")
    @classmethod
    def _unique(cls, v: list[Contestant]) -> list[Contestant]:
        return _unique_names(v, "contestant")


class SuiteRef(_Arena):
    """``config.yaml`` ``suite`` block."""

    config: str
    scale_episodes: float = Field(1.0, gt=0)
    worlds: str | None = Field(
        None, description="worlds folder for the suite's world names, relative to this file "
        "(our addition; replaces the suite's own)",
    )


class ContestRef(_Arena):
    """``config.yaml`` ``contest`` block."""

    config: str


class GeneralBlock(_Arena):
    """``config.yaml`` ``general`` block."""

    simulator: Literal["flatland", "gazebo", "unity", "native2d"] | str = "flatland"


class BenchmarkFile(_Arena):
    """Arena's benchmark ``config.yaml``."""

    suite: SuiteRef
    contest: ContestRef | None = None
    general: GeneralBlock = Field(default_factory=GeneralBlock)


def _validate(model: type[BaseModel], data: Any, source: str) -> Any:
    try:
        return model.model_validate(data)
    except ValidationError as e:
        raise from_validation_error(e, source=source) from None


def arena_stage_seed(raw: dict[str, Any]) -> int:
    """Arena's default stage seed: last 4 bytes of SHA-1 of the stage's JSON, as int32 >= 0."""
    digest = hashlib.sha1(json.dumps(raw, sort_keys=True, default=str).encode()).digest()
    return int.from_bytes(digest[-4:], "big") & 0x7FFFFFFF


def stage_run_seed(run_seed: int, stage_seed: int) -> int:
    """The seed a stage's episodes are drawn from, given the run's master seed."""
    return child_seed(int(run_seed), "benchmark", int(stage_seed))


class Suite:
    """A loaded suite: stages with their seeds, episode counts and source file.

    Attributes:
        stages: the stages in order.
        seeds: per stage, the stage seed (explicit, ``RANDOM.seed`` or Arena's SHA-1 default).
        source: the suite file.
        scale_episodes: factor on every stage's episode count (Arena: ``int(episodes × s)``).
        worlds: the worlds folder world names are looked up in first (see the module docs),
            checked to exist; ``None``: none.
        worlds_origin: where ``worlds`` came from, for messages (``--worlds``, a file's key).
    """

    def __init__(
        self, file: SuiteFile, raw: list[dict[str, Any]], source: str, scale_episodes: float = 1.0,
        *, worlds: Path | None = None, worlds_origin: str = "--worlds",
    ) -> None:
        if not (math.isfinite(scale_episodes) and scale_episodes > 0):
            raise ConfigError(f"scale_episodes must be a finite number > 0, got {scale_episodes}",
                              source=source)
        total = sum(st.episodes for st in file.stages) * scale_episodes
        if total > MAX_EPISODES:
            raise ConfigError(
                f"scale_episodes {scale_episodes:g} gives {total:.3g} episodes; a suite has at "
                f"most {MAX_EPISODES:,}", source=source,
            )
        self.stages = list(file.stages)
        self.source = source
        self.scale_episodes = float(scale_episodes)
        self.worlds = worlds
        self.worlds_origin = worlds_origin
        self.seeds = []
        for st, r in zip(self.stages, raw, strict=True):
            seed = st.seed if st.seed is not None else arena_stage_seed(r)
            rnd = st.config.RANDOM
            if rnd is not None and rnd.seed is not None and rnd.seed >= 0:
                seed = rnd.seed
            self.seeds.append(seed)

    @property
    def episode_counts(self) -> list[int]:
        """Episodes per stage after ``scale_episodes``."""
        return [int(st.episodes * self.scale_episodes) for st in self.stages]

    @property
    def total_episodes(self) -> int:
        """Episodes of the whole suite."""
        return sum(self.episode_counts)

    def locate(self, index: int) -> tuple[int, int]:
        """``(stage, local index)`` of the suite's episode ``index``."""
        if index < 0:
            raise IndexError(f"episode index must be >= 0, got {index}")
        rest = index
        for s, n in enumerate(self.episode_counts):
            if rest < n:
                return s, rest
            rest -= n
        raise IndexError(f"episode {index} is past the suite's {self.total_episodes} episodes")

    # -- stage → experiment ------------------------------------------------------------------
    def stage_map(self, i: int, base_map: dict[str, Any]) -> dict[str, Any]:
        """Stage ``i``'s map block (``base_map`` where the stage names none)."""
        st = self.stages[i]
        where = f"stages[{i}].map"
        m = st.map
        if m is None:
            return dict(base_map)
        if isinstance(m, dict):
            try:
                MAP_SOURCES.validate(m, source=self.source, path=where)
            except ConfigError as e:
                raise ConfigError(e.message, source=self.source, path=e.path or where) from None
            return dict(m)
        if m == "dynamic_map":  # Arena's map_file for generated maps
            if "generator" in MAP_SOURCES.entry(str(base_map.get("type"))).tags:
                return dict(base_map)
            return {"type": "rosnav_indoor"}
        try:
            name = find_stage_world(m, suite_file=Path(self.source), worlds=self.worlds,
                                    origin=self.worlds_origin)
        except ConfigError as e:
            raise ConfigError(e.message, source=self.source, path=where) from None
        return {"type": "world", "name": name}

    def stage_robot(self, i: int) -> str | None:
        """Stage ``i``'s robot: a preset name or a YAML path; ``None``: the run's.

        A relative YAML path is read relative to the suite file when the file exists there
        (as world folders are), else as given.
        """
        robot = self.stages[i].robot
        if robot is None or not robot.endswith((".yaml", ".yml")) or Path(robot).is_absolute():
            return robot
        near = Path(self.source).parent / robot
        return str(near.resolve()) if near.is_file() else robot

    def _world_folder(self, map_block: dict[str, Any]) -> Path | None:
        if map_block.get("type") != "world":
            return None
        return resolve_world(str(map_block["name"])).parent.parent

    def _scenario_file(self, i: int, map_block: dict[str, Any]) -> str:
        st = self.stages[i]
        name = st.config.SCENARIO.file if st.config.SCENARIO else "default.json"
        where = f"stages[{i}].config.SCENARIO.file"
        p = Path(name).expanduser()
        candidates = [p] if p.is_absolute() else []
        folder = self._world_folder(map_block)
        if folder is not None and not p.is_absolute():
            candidates.append(folder / "scenarios" / p)
        if not p.is_absolute():
            candidates.append(Path(self.source).resolve().parent / p)
        for c in candidates:
            if c.is_file():
                return str(c)
        looked = ", ".join(str(c) for c in candidates) or name
        raise ConfigError(f"scenario file {name!r} not found (looked at {looked})",
                          source=self.source, path=where)

    def stage_task(self, i: int, base_task: dict[str, Any], map_block: dict[str, Any]) -> dict:
        """Stage ``i``'s ``task`` block: base, then Arena's overlay, then the ``task:`` overlay."""
        st = self.stages[i]
        cfg = st.config
        task = {k: v for k, v in base_task.items() if k not in ("robots", "obstacles")}
        task["modules"] = []
        scenario = None
        if "scenario" in (st.tm_robots, st.tm_obstacles):
            scenario = self._scenario_file(i, map_block)
        robots: dict[str, Any] = {"type": st.tm_robots}
        if st.tm_robots == "scenario":
            robots["file"] = scenario
        elif base_task.get("robots", {}).get("type") == st.tm_robots:
            robots = dict(base_task["robots"])
        obstacles: dict[str, Any] = {"type": st.tm_obstacles}
        if st.tm_obstacles == "scenario":
            obstacles["file"] = scenario
        elif st.tm_obstacles == "random":
            if base_task.get("obstacles", {}).get("type") == "random":
                obstacles = json.loads(json.dumps(base_task["obstacles"]))
            rnd = cfg.RANDOM
            for cls in ("static", "interactive", "dynamic"):
                c = getattr(rnd, cls) if rnd is not None else None
                if c is None:
                    continue
                old = obstacles.get(cls, {})
                block: dict[str, Any] = dict(old) if isinstance(old, dict) else {}
                if isinstance(old, int) and not isinstance(old, bool):
                    block = {"min": old, "max": old}
                elif isinstance(old, list):
                    block = {"min": old[0], "max": old[1]}
                if c.min is not None:
                    block["min"] = c.min
                if c.max is not None:
                    block["max"] = c.max
                if c.min is not None and c.max is None:
                    block["max"] = max(c.min, int(block.get("max", c.min)))
                # Pedestrian models (actor1 ...) are Arena meshes: ignored (see module docs).
                if c.models is not None and cls != "dynamic":
                    block["models"] = list(c.models)
                obstacles[cls] = block
        task["robots"] = robots
        task["obstacles"] = obstacles
        if cfg.timeout is not None:
            task["timeout"] = cfg.timeout if cfg.timeout > 0 else 1e9
        if st.timeout is not None:
            task["timeout"] = st.timeout
        for key in ("goal_radius", "goal_tolerance_angle"):
            if getattr(cfg, key) is not None:
                task[key] = getattr(cfg, key)
        if st.task is not None:
            task = merge(task, st.task)
        return task

    def stage_experiments(
        self, base_cfg: ExperimentConfig
    ) -> list[tuple[SuiteStage, ExperimentConfig]]:
        """One experiment per stage (:meth:`stage_experiment`), stages scaled to 0 left out.

        Raises:
            ConfigError: as :meth:`stage_experiment`, for the first stage that fails.
        """
        return [(st, self.stage_experiment(i, base_cfg))
                for i, (st, n) in enumerate(zip(self.stages, self.episode_counts, strict=True))
                if n > 0]

    def stage_experiment(self, i: int, base_cfg: ExperimentConfig) -> ExperimentConfig:
        """Stage ``i`` as an experiment, run on its own equal to the stage inside the suite.

        The experiment's seed is :func:`stage_run_seed` of ``base_cfg.seed`` and the stage
        seed; a generated map that changes per episode gets ``dynamic_map`` (one map per
        episode). Its episodes are the stage's after ``scale_episodes`` (at least 1, so that a
        stage scaled away can still be drawn on its own).

        Raises:
            ConfigError: a missing world or scenario, an unknown mode or model, naming the
                suite file and the stage's key path (``stages[3].map``).
        """
        base = base_cfg.model_dump(mode="json")
        st = self.stages[i]
        map_block = self.stage_map(i, base["map"])
        try:
            task = self.stage_task(i, base["task"], map_block)
        except ConfigError as e:
            if e.source is None:
                raise e.located(source=self.source, prefix=f"stages[{i}]") from None
            raise
        if self.is_generated(map_block) and st.map_per_episode:
            task["modules"] = [{"type": "dynamic_map", "episodes_per_map": 1},
                               *task.get("modules", [])]
        data = {
            **base,
            "name": f"{base_cfg.name}/{st.name}",
            "seed": stage_run_seed(base_cfg.seed, self.seeds[i]),
            "episodes": max(self.episode_counts[i], 1),
            "robot": self.stage_robot(i) or base["robot"],
            "map": map_block,
            "task": task,
        }
        try:
            cfg = ExperimentConfig.model_validate(data)
        except ValidationError as e:
            err = from_validation_error(e, source=self.source)
            raise _stage_error(err, i, self.source) from None
        try:
            validate_plugins(cfg, source=self.source)
        except ConfigError as e:
            raise _stage_error(e, i, self.source) from None
        return cfg

    @staticmethod
    def is_generated(map_block: dict[str, Any]) -> bool:
        """Whether a map block names a procedural generator (a new map per seed/key)."""
        try:
            return "generator" in MAP_SOURCES.entry(str(map_block.get("type"))).tags
        except ConfigError:
            return False


_STAGE_KEYS = {
    "robot": "robot",
    "map": "map",
    "task.robots": "tm_robots",
    "task.obstacles": "config.RANDOM",
    "task": "task",
}


def _stage_error(err: ConfigError, i: int, source: str) -> ConfigError:
    """Name the stage key a problem in the derived experiment comes from."""
    path = err.path or ""
    where = f"stages[{i}]"
    for prefix, key in _STAGE_KEYS.items():
        if path == prefix or path.startswith(prefix + ".") or path.startswith(prefix + "["):
            where = f"stages[{i}].{key}"
            break
    detail = f" ({path})" if path else ""
    return ConfigError(err.message + detail, source=source, path=where)


def load_suite(
    name_or_path: str | Path, *, scale_episodes: float = 1.0, worlds: str | Path | None = None,
    worlds_option: str = "--worlds",
) -> Suite:
    """Load a packaged suite (``"paper"``, ``"quick"``) or a suite file.

    Only the file's structure and the worlds folder are checked here; worlds and scenarios are
    resolved by :meth:`Suite.stage_experiments`.

    Args:
        name_or_path: packaged name or suite file.
        scale_episodes: factor on every stage's episode count.
        worlds: the worlds folder (see the module docs); replaces the file's ``worlds:`` key.
        worlds_option: what ``worlds`` is called in messages (the CLI option, a config key).

    Raises:
        ConfigError: a bad file, or a worlds folder that does not exist (naming where it was
            given).
    """
    path = find_data_file("suites", name_or_path)
    source = str(path)
    data = read_arena_yaml(path)
    if not isinstance(data, dict):
        raise ConfigError(
            f"expected a mapping {{stages: [...]}}, got {type(data).__name__}", source=source
        )
    file = _validate(SuiteFile, data, source)
    if worlds is not None:
        folder = check_worlds_folder(worlds, source=worlds_option)
        origin = worlds_option
    elif file.worlds is not None:
        folder = check_worlds_folder(path.parent / file.worlds, source=source, path="worlds")
        origin = f"{source}: worlds"
    else:
        folder, origin = None, worlds_option
    return Suite(file, list(data["stages"]), source, scale_episodes, worlds=folder,
                 worlds_origin=origin)


def load_contest(name_or_path: str | Path) -> tuple[ContestFile, str]:
    """Load a packaged contest (``"basic"``) or a contest file; returns it and its path."""
    path = find_data_file("contests", name_or_path)
    data = read_arena_yaml(path)
    return _validate(ContestFile, data, str(path)), str(path)


def contestant_config(
    base_cfg: ExperimentConfig, contestant: Contestant, *, source: str | None = None, index: int = 0
) -> ExperimentConfig:
    """``base_cfg`` driven by the contestant's local planner (and global planner, if named).

    ``inter_planner`` (Arena's intermediate planner: ``bypass``, ``polite``, ``aggressive`` ...,
    all registered intermediate planners) is set by :func:`arena.eval.runner.plan_jobs`, not
    here. A local planner alias (``rosnav``) is kept as written; it builds its target.
    """
    where = f"contestants[{index}].local_planner"
    try:
        LOCAL_PLANNERS.entry(contestant.local_planner)
    except ConfigError as e:
        raise ConfigError(e.message, source=source, path=where) from None
    data = base_cfg.model_dump(mode="json")
    own = sorted(set(contestant.navigation) & _OWN_KEYS)
    if own:
        raise ConfigError(
            f"set {own[0]} with the contestant's own key, not under navigation",
            source=source, path=f"contestants[{index}].navigation.{own[0]}",
        )
    data["navigation"] = merge(data["navigation"], contestant.navigation)
    nav = data["navigation"]
    block = {**contestant.params, "type": contestant.local_planner}
    try:
        LOCAL_PLANNERS.validate(block, path="local_planner")
    except ConfigError as e:
        sub = (e.path or "").removeprefix("local_planner").lstrip(".")
        path = f"contestants[{index}].params" + (f".{sub}" if sub else "")
        raise ConfigError(e.message, source=source, path=path) from None
    nav["local_planner"] = block
    if contestant.global_planner is not None:
        gp = contestant.global_planner
        gp_block = {"type": gp} if isinstance(gp, str) else dict(gp)
        GLOBAL_PLANNERS.validate(gp_block, source=source,
                                 path=f"contestants[{index}].global_planner")
        nav["global_planner"] = gp_block
    if contestant.perception is not None:
        PERCEPTION.validate(contestant.perception, source=source,
                            path=f"contestants[{index}].perception")
        nav["perception"] = contestant.perception
    try:
        return ExperimentConfig.model_validate({**data, "name": contestant.name})
    except ValidationError as e:
        if not contestant.navigation:
            raise
        err = from_validation_error(e, source=source)
        path = (err.path or "").replace("navigation", f"contestants[{index}].navigation", 1)
        raise ConfigError(err.message, source=source, path=path) from None


_OWN_KEYS = frozenset({"local_planner", "global_planner", "intermediate_planner", "perception"})
"""Navigation keys a contestant sets with its own fields, not through ``navigation``."""


def load_benchmark(
    path: str | Path, *, worlds: str | Path | None = None
) -> tuple[Suite, tuple[ContestFile, str] | None]:
    """Arena's benchmark ``config.yaml``: the suite (scaled) and the contest, if any.

    ``suite.config`` / ``contest.config`` are looked up in the ``suites/`` / ``contests/``
    folders next to the file (Arena's layout), then as paths and packaged names. ``worlds``
    (the ``--worlds`` option) replaces ``suite.worlds``, which replaces the suite's own.
    """
    p = Path(path)
    data = read_arena_yaml(p)
    bench = _validate(BenchmarkFile, data, str(p))

    def find(folder: str, name: str) -> str:
        for c in (p.parent / folder / name, p.parent / folder / f"{name}.yaml"):
            if c.is_file():
                return str(c)
        return name

    option = "--worlds"
    if worlds is None and bench.suite.worlds is not None:
        worlds, option = p.parent / bench.suite.worlds, f"{p}: suite.worlds"
    suite = load_suite(find("suites", bench.suite.config),
                       scale_episodes=bench.suite.scale_episodes, worlds=worlds,
                       worlds_option=option)
    contest = load_contest(find("contests", bench.contest.config)) if bench.contest else None
    return suite, contest
