"""Pedestrian social states (Arena's crowdsim statechart).

Split into parameters, perception and the statechart itself; :mod:`arena.crowd.social_states`
re-exports the public names.
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
