"""Pedestrian social states: the public entry point.

The implementation lives in :mod:`arena.crowd.social` (``params``: distributions and their
sampling; ``perception``: vision; ``statechart``: :class:`SocialStates`). Import from here::

    from arena.crowd.social_states import SocialStates, SocialStatesParams

    social = SocialStates(SocialStatesParams())
    social.reset(state, world, rng)               # once per episode
    social.pre(state, robots, world, dt)          # before the crowd model
    acc = social.post(state, acc, dt)             # on the model's accelerations
    social.orient(state)                          # after integration
"""

from arena.crowd.social import (
    TARGET_AGENT,
    TARGET_NONE,
    TARGET_POINT,
    TARGET_ROBOT,
    Dist,
    ElderOffsets,
    HumanParams,
    RobotAvoidanceParams,
    SocialStates,
    SocialStatesParams,
    Vision,
    VmaxFactors,
    sample_agent_params,
    sees,
    truncated_normal,
)

__all__ = [
    "TARGET_AGENT",
    "TARGET_NONE",
    "TARGET_POINT",
    "TARGET_ROBOT",
    "Dist",
    "ElderOffsets",
    "HumanParams",
    "RobotAvoidanceParams",
    "SocialStates",
    "SocialStatesParams",
    "Vision",
    "VmaxFactors",
    "sample_agent_params",
    "sees",
    "truncated_normal",
]
