"""``modules.clear_forbidden_zones``: start every reset with an empty forbidden layer.

Arena appends this module always because its world manager outlives resets and would otherwise
pile up the forbidden squares of earlier episodes. Here every episode gets a fresh layer, seeded
with the config's ``task.forbidden_zones``; this module empties that too, for a stage or run that
should ignore the configured keep-out zones (zones the modes add during the reset, such as robot
starts and goals, still apply).
"""

from __future__ import annotations

from arena.tasks.base import ModuleBase, ResetContext, register_mode


@register_mode("modules", "clear_forbidden_zones")
class ClearForbiddenZones(ModuleBase):
    """Drop the configured forbidden zones before each reset."""

    def before_reset(self, ctx: ResetContext) -> None:
        """Empty ``ctx.forbidden``."""
        ctx.forbidden.clear()
