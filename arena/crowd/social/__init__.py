"""Pedestrian social states (Arena's crowdsim statechart).

Split into ``params`` (distributions and their sampling), ``perception`` (vision),
``kernels`` (one tick of the statechart, compiled) and ``statechart`` (:class:`SocialStates`).
Use::

    from arena.crowd.social import SocialStates, SocialStatesParams

    social = SocialStates(SocialStatesParams())
    social.reset(state, world, rng)               # once per episode
    social.pre(state, robots, world, dt)          # before the crowd model
    acc = social.post(state, acc, dt)             # on the model's accelerations
    social.orient(state)                          # after integration
"""

from arena.crowd.social.params import (
    Dist,
    ElderOffsets,
    HumanParams,
    RobotAvoidanceParams,
    SocialStatesParams,
    VmaxFactors,
    sample_agent_params,
    truncated_normal,
)
from arena.crowd.social.perception import Vision, sees
from arena.crowd.social.statechart import (
    TARGET_AGENT,
    TARGET_NONE,
    TARGET_POINT,
    TARGET_ROBOT,
    SocialStates,
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
