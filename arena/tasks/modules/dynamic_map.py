"""``modules.dynamic_map``: a newly generated map every ``episodes_per_map`` episodes.

Arena's module counts episodes over all environments and asks the map generator node for a new
map (specs §2.8). Here the map of episode ``i`` is map instance ``i // episodes_per_map`` of the
``map`` block, drawn from its own seed: the same episode always gets the same map, whichever
worker draws it. Without this module every episode of a run shares map instance 0.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field

from arena.tasks.base import ModuleBase, ResetContext, register_mode


@register_mode("modules", "dynamic_map")
class DynamicMap(ModuleBase):
    """Switch to a new generated map every ``episodes_per_map`` episodes."""

    class Params(BaseModel):
        """Parameters of ``modules.dynamic_map``."""

        model_config = ConfigDict(frozen=True, extra="forbid")
        episodes_per_map: int = Field(1, ge=1, description="episodes played on one map")

    def __init__(self, params: Params | None = None) -> None:
        self.params = params or self.Params()

    def before_reset(self, ctx: ResetContext) -> None:
        """Select map instance ``index // episodes_per_map``."""
        ctx.map_key = ctx.index // self.params.episodes_per_map
