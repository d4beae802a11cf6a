"""``modules.staged``: a training curriculum of stages (Arena specs §2.8).

Each stage fixes the obstacle counts (Arena sets RANDOM min = max = the stage's count), may set
the goal radius and may switch the map generator. The stage changes when a trainer calls
:meth:`Staged.promote` / :meth:`Staged.demote` / :meth:`Staged.report` (Arena's
``next_stage``/``previous_stage`` topics and its training callback), or, with ``auto: true``,
from the success rate of the last ``window`` episodes reported through ``on_episode_end``.
The stage index is clamped to the curriculum, as in Arena.
"""

from __future__ import annotations

import collections
from typing import Any

from pydantic import BaseModel, ConfigDict, Field

from arena.core.errors import ConfigError
from arena.maps.generators import MAP_GENERATORS
from arena.maps.sources import MAP_SOURCES
from arena.tasks.base import ModuleBase, ObstacleCounts, ResetContext, register_mode
from arena.tasks.curriculum import Curriculum, CurriculumStage, load_curriculum


@register_mode("modules", "staged")
class Staged(ModuleBase):
    """Curriculum stages: obstacle counts, goal radius and map per stage."""

    class Params(BaseModel):
        """Parameters of ``modules.staged``."""

        model_config = ConfigDict(frozen=True, extra="forbid")
        curriculum: str = Field(
            "default", description="packaged curriculum (default, semantic) or a YAML path"
        )
        index: int = Field(0, ge=0, description="stage to start in (Arena: STAGED.index)")
        auto: bool = Field(
            False, description="promote/demote from the success rate of the last `window` episodes"
        )
        upper_threshold: float | None = Field(
            None, ge=0, le=1, description="success rate that promotes; None: the curriculum's"
        )
        lower_threshold: float | None = Field(
            None, ge=0, le=1, description="success rate that demotes; None: the curriculum's"
        )
        window: int | None = Field(
            None, ge=1, description="episodes of the auto mode's success rate; None: curriculum's"
        )

    def __init__(self, params: Params | None = None) -> None:
        self.params = p = params or self.Params()
        self.curriculum: Curriculum = load_curriculum(p.curriculum)
        n = len(self.curriculum)
        if p.index >= n:
            raise ConfigError(
                f"start stage {p.index} does not exist: the curriculum has {n} stages (0-{n - 1})",
                source=self.curriculum.source,
                path="index",
            )
        self.upper_threshold = (
            p.upper_threshold if p.upper_threshold is not None else self.curriculum.upper_threshold
        )
        self.lower_threshold = (
            p.lower_threshold if p.lower_threshold is not None else self.curriculum.lower_threshold
        )
        if self.lower_threshold > self.upper_threshold:
            raise ConfigError(
                f"lower_threshold ({self.lower_threshold}) exceeds upper_threshold "
                f"({self.upper_threshold})",
                path="lower_threshold",
            )
        self.window = p.window if p.window is not None else self.curriculum.window
        self._stage = p.index
        self._outcomes: collections.deque[bool] = collections.deque(maxlen=self.window)
        self._maps: dict[tuple[int, str], dict[str, Any]] = {}

    # -- public API for trainers ---------------------------------------------------------------
    @property
    def stage(self) -> int:
        """The current stage index (0 = easiest)."""
        return self._stage

    @property
    def num_stages(self) -> int:
        """Stages in the curriculum."""
        return len(self.curriculum)

    @property
    def current(self) -> CurriculumStage:
        """The current stage's settings."""
        return self.curriculum.stages[self._stage]

    @property
    def is_last(self) -> bool:
        """Whether the current stage is the last one (Arena stops training there at 0.98)."""
        return self._stage == len(self.curriculum) - 1

    def set_stage(self, index: int) -> int:
        """Go to stage ``index`` (clamped to the curriculum); return the new stage."""
        new = min(max(int(index), 0), len(self.curriculum) - 1)
        if new != self._stage:
            self._outcomes.clear()
        self._stage = new
        return new

    def promote(self) -> bool:
        """Next stage (Arena's ``next_stage``); ``False`` if already at the last one."""
        old = self._stage
        return self.set_stage(old + 1) != old

    def demote(self) -> bool:
        """Previous stage (Arena's ``previous_stage``); ``False`` if already at the first one."""
        old = self._stage
        return self.set_stage(old - 1) != old

    def report(self, success_rate: float) -> int:
        """Apply Arena's training callback to an evaluation success rate (0-1).

        Returns:
            +1 if promoted (rate >= upper_threshold), -1 if demoted (rate <= lower_threshold),
            0 if the stage did not change (including at either end of the curriculum).
        """
        if not 0.0 <= success_rate <= 1.0:
            raise ValueError(f"success_rate must be in [0, 1], got {success_rate}")
        if success_rate >= self.upper_threshold:
            return 1 if self.promote() else 0
        if success_rate <= self.lower_threshold:
            return -1 if self.demote() else 0
        return 0

    # -- hooks ---------------------------------------------------------------------------------
    def before_reset(self, ctx: ResetContext) -> None:
        """Impose the stage's counts, goal radius and map on the episode."""
        st = self.current
        ctx.counts = ObstacleCounts(static=st.static, interactive=st.interactive,
                                    dynamic=st.dynamic)
        if st.goal_radius is not None:
            ctx.goal_radius = st.goal_radius
        if self.curriculum.map_specs[self._stage] is not None:
            ctx.map_spec = self._map_spec(ctx)
        ctx.label = f"stage {self._stage}"

    def on_episode_end(self, index: int, outcome: str) -> None:
        """In auto mode, promote/demote once ``window`` outcomes have been seen in this stage."""
        if not self.params.auto:
            return
        self._outcomes.append(str(outcome) == "success")
        if len(self._outcomes) == self.window:
            rate = sum(self._outcomes) / self.window
            if self.report(rate) == 0:
                return
            self._outcomes.clear()

    def _map_spec(self, ctx: ResetContext) -> dict[str, Any]:
        """The stage's generator block, keeping the run's map size and the robot's radius.

        Arena's generator reads ``map_properties`` (size) and the robot's radius from the run;
        here the run's ``width``/``height`` (if its map block has them and the generator takes
        them) and the largest robot radius (m, for the barn connectivity check) are added
        unless the stage sets them. If the run's size does not fit the generator (not a whole
        number of its cells) the generator's own size is used.
        """
        base = self.curriculum.map_specs[self._stage]
        assert base is not None
        key = (self._stage, repr(sorted(ctx.map_spec.items())))
        if key in self._maps:
            return dict(self._maps[key])
        spec = dict(base)
        model = MAP_GENERATORS.entry(spec["type"]).params_model
        fields = set(model.model_fields) if model is not None else set()
        extra: dict[str, Any] = {}
        for name in ("width", "height"):
            if name in fields and name not in spec and name in ctx.map_spec:
                extra[name] = ctx.map_spec[name]
        if "robot_radius" in fields and "robot_radius" not in spec and ctx.robots:
            extra["robot_radius"] = max(r.radius for r in ctx.robots)
        candidate = {**spec, **extra}
        try:
            MAP_SOURCES.validate(candidate)
        except ConfigError:
            candidate = {**spec, **{k: v for k, v in extra.items() if k == "robot_radius"}}
        self._maps[key] = candidate
        return dict(candidate)
