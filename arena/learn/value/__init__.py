"""Value-network crowd policies (CrowdNav's CADRL and SARL), numpy only.

Chen, Liu, Kreiss & Alahi 2019, "Crowd-Robot Interaction: Crowd-aware Robot Navigation with
Attention-based Deep Reinforcement Learning" (ICRA), code ``vita-epfl/CrowdNav``; with the local
goal and laser pruning of SARL* (Li, Ding, Li, Gao, Wang & Chen 2019, "Role of Human-Robot
Interaction in Crowd-Robot Navigation", ROBIO).

- :mod:`.state`: the joint state and its rotation into the agent-centred frame.
- :mod:`.actions`: CrowdNav's discrete action sets and the one-step lookahead.
- :mod:`.network`: the CADRL and SARL value networks in numpy and their ``.npz`` file format.
- :mod:`.train`: imitation from ORCA then RL, in our simulator (torch; the ``train`` extra).

The ``crowdnav`` and ``sarl`` local planners (:mod:`arena.learn.planners.crowdnav`) run
them. Nothing here imports torch or gymnasium except :mod:`.train`.
"""

from arena.learn.value.actions import ActionSet, Lookahead, build_action_set, lookahead
from arena.learn.value.network import (
    CadrlNetwork,
    SarlNetwork,
    ValueNetwork,
    ValuePolicyFile,
    load_value_policy,
    save_value_policy,
)
from arena.learn.value.state import (
    HUMAN_DIM,
    PAIR_DIM,
    SELF_DIM,
    JointState,
    joint_state,
    rotate,
)

__all__ = [
    "HUMAN_DIM",
    "PAIR_DIM",
    "SELF_DIM",
    "ActionSet",
    "CadrlNetwork",
    "JointState",
    "Lookahead",
    "SarlNetwork",
    "ValueNetwork",
    "ValuePolicyFile",
    "build_action_set",
    "joint_state",
    "load_value_policy",
    "lookahead",
    "rotate",
    "save_value_policy",
]
