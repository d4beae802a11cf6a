"""Parameters of the social-state statechart and their per-agent sampling.

Every per-agent quantity of Arena's ``Human`` statechart (crowdsim ``states/human/human.py``) is a
:class:`Dist`: a normal distribution truncated to optional bounds. At
:meth:`~arena.crowd.social.statechart.SocialStates.reset` each agent draws its own value once, so
a crowd has a spread of temperaments. Elders shift some means by whole standard deviations
(:class:`ElderOffsets`), exactly as Arena's ``Elder`` class does.

Defaults are Arena's values (arena_specs §5.2); units are SI unless a field says otherwise
(``vision_angle`` stays in degrees, as in Arena's config, to keep the numbers recognisable).
"""

from __future__ import annotations

import functools
import math
from typing import Self

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator
from scipy.special import ndtr, ndtri

FloatArray = NDArray[np.float64]


class Dist(BaseModel):
    """A normal distribution truncated to ``[lo, hi]`` (either bound optional).

    Attributes:
        mean: location of the untruncated normal.
        sigma: its standard deviation (≥ 0; 0 gives the constant ``mean`` clipped to the bounds).
        lo: lower bound, or ``None`` for none.
        hi: upper bound, or ``None`` for none.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    mean: float
    sigma: float = Field(0.0, ge=0.0)
    lo: float | None = None
    hi: float | None = None

    @model_validator(mode="after")
    def _check_bounds(self) -> Self:
        if self.lo is not None and self.hi is not None and self.lo > self.hi:
            raise ValueError(f"lo ({self.lo}) must not exceed hi ({self.hi})")
        return self

    def shifted(self, k: float) -> Dist:
        """The same distribution with its mean moved by ``k`` standard deviations."""
        return self.model_copy(update={"mean": self.mean + k * self.sigma})

    def sample(self, n: int, rng: np.random.Generator) -> FloatArray:
        """``(n,)`` independent draws (one uniform per draw, even when ``sigma`` is 0)."""
        return truncated_normal(np.full(n, self.mean), self.sigma, self.lo, self.hi, rng.random(n))


def truncated_normal(
    mean: FloatArray, sigma: float, lo: float | None, hi: float | None, u: FloatArray
) -> FloatArray:
    """Inverse-CDF draws of ``N(mean, sigma²)`` truncated to ``[lo, hi]``.

    Args:
        mean: ``(n,)`` means.
        sigma: standard deviation (≥ 0).
        lo: lower bound or ``None``.
        hi: upper bound or ``None``.
        u: ``(n,)`` uniforms in ``[0, 1)``, one per draw.

    Returns:
        ``(n,)`` samples, always inside the bounds.
    """
    mean = np.asarray(mean, dtype=np.float64)
    lo_v = -math.inf if lo is None else float(lo)
    hi_v = math.inf if hi is None else float(hi)
    if sigma <= 0.0:
        return np.clip(mean, lo_v, hi_v)
    return _truncated_normal_rows(mean, sigma, lo_v, hi_v, u)


def _nd(mean: float, sigma: float, lo: float | None = None, hi: float | None = None) -> Dist:
    return Dist(mean=mean, sigma=sigma, lo=lo, hi=hi)


def _snd(mean: float, sigma: float) -> Dist:
    """A level threshold: normal truncated to ``[0, 1]`` (Arena's ``SND``)."""
    return Dist(mean=mean, sigma=sigma, lo=0.0, hi=1.0)


class VmaxFactors(BaseModel):
    """Multipliers on each agent's preferred speed ``vmax`` per social state.

    Arena only sets running ×2 and phone ×0.5 (``Human.post``); standing states stand.

    Attributes:
        walking: 1.0.
        idle: 0.0 (stands still).
        running: 2.0 (Arena).
        phone: 0.5 (Arena).
        panic: 2.0 (the one-tick transient before running; as running).
        approach: 1.0, talking and interacting agents on their way to their spot.
        talking: 0.0, once gathered at the talking spot (they stand and face each other).
        interacting: 0.0, once at the interaction spot (they stand and face the target).
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    walking: float = Field(1.0, ge=0.0)
    idle: float = Field(0.0, ge=0.0)
    running: float = Field(2.0, ge=0.0)
    phone: float = Field(0.5, ge=0.0)
    panic: float = Field(2.0, ge=0.0)
    approach: float = Field(1.0, ge=0.0)
    talking: float = Field(0.0, ge=0.0)
    interacting: float = Field(0.0, ge=0.0)


LEVEL_NAMES = ("stress", "energy", "social")
STATE_RATE_PREFIXES = ("idle", "walking", "running", "interacting", "talking", "phone")


class HumanParams(BaseModel):
    """Per-agent parameters of an adult (Arena's ``Human``), each a :class:`Dist`.

    Levels are dimensionless in ``[0, 1]``; rates are level units per second.

    Attributes:
        min_time_in_state: s, N(2.0, 0.5) ≥ 1.0; no transition out of a state before this.
        stress_lo, stress_hi, energy_lo, energy_hi, social_lo, social_hi: thresholds,
            N(0.20, 0.05) / N(0.80, 0.05) truncated to [0, 1].
        d_stress: drift /s, N(−0.01, 0.001) ≤ −0.001.
        d_energy: drift /s, N(+0.01, 0.001) ≥ 0.001.
        d_social: drift /s, N(+0.01, 0.001) ≥ 0.001.
        idle_d_*: /s while idle: stress −0.05, energy +0.15, social +0.05 (σ 0.001).
        walking_d_*: /s while walking: 0, 0, 0 (σ 0.001).
        running_d_*: /s while running (and panicking): 0, −0.05, 0 (σ 0.01).
        interacting_d_*: /s while interacting: 0, −0.05, +0.05 (σ 0.01).
        talking_d_*: /s while talking: 0, 0, −0.05 (σ 0.01).
        phone_d_*: /s while on the phone: 0, 0, −0.05 (σ 0.01).
        vision_range: m, N(5.0, 0.5) ≥ 0.
        vision_angle: degrees, half-angle of the vision cone around the heading, N(45, 5) in
            [0, 90].
        personal_space_radius: m, N(1.0, 0.1) ≥ 0.5; robots inside it frighten, anything inside
            1.1× it is perceived whatever the direction, talking and interest keep this distance.
        fear_robot: stress per Arena tick while a robot is inside the personal space,
            N(0.02, 0.001) (see ``SocialStatesParams.fear_rate_hz``).
        fear_robot_speed_tolerance: m/s, N(0.7, 0.1) ≥ 0; robot speed above it adds stress.
        vmax_factors: speed multipliers per state (constants, not distributions).
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    min_time_in_state: Dist = _nd(2.0, 0.5, 1.0)

    stress_lo: Dist = _snd(0.20, 0.05)
    stress_hi: Dist = _snd(0.80, 0.05)
    energy_lo: Dist = _snd(0.20, 0.05)
    energy_hi: Dist = _snd(0.80, 0.05)
    social_lo: Dist = _snd(0.20, 0.05)
    social_hi: Dist = _snd(0.80, 0.05)

    d_stress: Dist = _nd(-0.01, 0.001, None, -0.001)
    d_energy: Dist = _nd(+0.01, 0.001, 0.001, None)
    d_social: Dist = _nd(+0.01, 0.001, 0.001, None)

    idle_d_stress: Dist = _nd(-0.05, 0.001)
    idle_d_energy: Dist = _nd(+0.15, 0.001)
    idle_d_social: Dist = _nd(+0.05, 0.001)
    walking_d_stress: Dist = _nd(0.0, 0.001)
    walking_d_energy: Dist = _nd(0.0, 0.001)
    walking_d_social: Dist = _nd(0.0, 0.001)
    running_d_stress: Dist = _nd(0.0, 0.01)
    running_d_energy: Dist = _nd(-0.05, 0.01)
    running_d_social: Dist = _nd(0.0, 0.01)
    interacting_d_stress: Dist = _nd(0.0, 0.01)
    interacting_d_energy: Dist = _nd(-0.05, 0.01)
    interacting_d_social: Dist = _nd(+0.05, 0.01)
    talking_d_stress: Dist = _nd(0.0, 0.01)
    talking_d_energy: Dist = _nd(0.0, 0.01)
    talking_d_social: Dist = _nd(-0.05, 0.01)
    phone_d_stress: Dist = _nd(0.0, 0.01)
    phone_d_energy: Dist = _nd(0.0, 0.01)
    phone_d_social: Dist = _nd(-0.05, 0.01)

    vision_range: Dist = _nd(5.0, 0.5, 0.0)
    vision_angle: Dist = _nd(45.0, 5.0, 0.0, 90.0)
    personal_space_radius: Dist = _nd(1.0, 0.1, 0.5)
    fear_robot: Dist = _nd(0.02, 0.001)
    fear_robot_speed_tolerance: Dist = _nd(0.7, 0.1, 0.0)

    vmax_factors: VmaxFactors = VmaxFactors()

    @classmethod
    def dist_names(cls) -> tuple[str, ...]:
        """Names of the per-agent distributed parameters, in declaration order."""
        return tuple(k for k, f in cls.model_fields.items() if f.annotation in (Dist, "Dist"))


_ELDER_OFFSETS = {
    "min_time_in_state": +2.0,  # a little slower
    "energy_lo": +2.0,  # tires more easily
    "social_lo": -2.0,  # chats longer
    "social_hi": +2.0,
    "d_stress": -3.0,
    "d_energy": -3.0,
    "d_social": +3.0,
    "vision_range": -3.0,
    "vision_angle": -1.0,
    "personal_space_radius": +2.0,
    "fear_robot": +2.0,
    "fear_robot_speed_tolerance": -2.0,
}


class ElderOffsets(BaseModel):
    """How an elder differs from an adult (Arena's ``Elder``).

    Attributes:
        offsets: ``name -> k``: the elder's mean is the adult mean + k·σ (same σ and bounds).
            Default (Arena): min_time_in_state +2, energy_lo +2, social_lo −2, social_hi +2,
            d_stress −3, d_energy −3, d_social +3, vision_range −3, vision_angle −1,
            personal_space_radius +2, fear_robot +2, fear_robot_speed_tolerance −2.
        constants: ``name -> value`` fixed for every elder. Default ``energy_hi = 1`` (elders
            never start running on their own: ``max(0, energy − 1)`` is always 0).
    Elders' slower walking (pedsim's ×0.7) is not here: the crowd simulator applies it
    (``PedestrianConfig.elder_speed_factor``), so it holds with social states off too.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    offsets: dict[str, float] = Field(default_factory=lambda: dict(_ELDER_OFFSETS))
    constants: dict[str, float] = Field(default_factory=lambda: {"energy_hi": 1.0})

    @field_validator("offsets", "constants")
    @classmethod
    def _known(cls, v: dict[str, float]) -> dict[str, float]:
        unknown = set(v) - set(HumanParams.dist_names())
        if unknown:
            raise ValueError(f"unknown human parameters: {sorted(unknown)}")
        return v


class RobotAvoidanceParams(BaseModel):
    """Table II "robot avoidance": pedestrians keep slowly away from robots.

    The repulsion on agent ``i`` from robot ``k`` is
    ``strength · exp(−gap / (range_factor · psr_i)) · n̂`` with ``gap`` the clearance between
    the agent's and the robot's circles (m), ``n̂`` the unit vector from the robot to the
    agent and ``psr_i`` the agent's personal-space radius; zero beyond
    ``cutoff_factor · psr_i`` of clearance.

    Attributes:
        enabled: add the term in :meth:`SocialStates.post` (default False: most crowd models
            have their own robot force; enable it for models that ignore robots).
        strength: m/s², acceleration at contact, 1.0.
        range_factor: decay length in units of the personal-space radius, 0.5.
        cutoff_factor: clearance (in personal-space radii) beyond which the term is 0, 2.0.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    enabled: bool = False
    strength: float = Field(1.0, ge=0.0)
    range_factor: float = Field(0.5, gt=0.0)
    cutoff_factor: float = Field(2.0, gt=0.0)


class SocialStatesParams(BaseModel):
    """Everything the statechart needs.

    Attributes:
        human: adult parameters (also used for children and unknown types, as Arena does).
        elder: elder offsets.
        robot_avoidance: the optional robot-avoidance acceleration.
        fear_rate_hz: Hz. Arena adds ``fear_robot + max(0, ‖v_robot‖ − tolerance)`` to stress
            once per crowdsim tick, unscaled by dt; we add ``dt · fear_rate_hz`` times that, so
            the result no longer depends on the step length and equals Arena's at its 24 Hz
            tick (pedsim ``update_rate``). Default 24.
        gather_tolerance: m, a talking or interacting agent within this of its spot has
            gathered and stands (0.25; larger than the 0.1 m at-destination radius because the
            partner's social repulsion keeps agents from reaching the exact spot).
        at_destination_radius: m, Arena's "at destination" radius, 0.1.
        at_destination_force: Arena's residual acceleration magnitude there, 0.01 (m/s²).
        at_destination_vmax_factor: Arena's vmax factor there, 0.01.
        interested_in_robots: robots seen by an energetic resting agent count as interaction
            targets (Table II "interested": approach the robot to personal-space distance).
            Default True.
        interact_with_walls: map walls count as interaction targets too (default False: Arena
            only approaches placed obstacles, and with walls on, agents in corridors would
            always pick a wall and never run).
        idle_recovery: idle agents walk again once ``energy ≥ energy_lo + idle_recovery ·
            (energy_hi − energy_lo)`` (default 0.5, the middle of the band).
        wake_on_approach: idle agents walk again when another agent or a robot comes within
            1.1 personal-space radii (Table II: "standing, will move once objects approach").
            Default True.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    human: HumanParams = HumanParams()
    elder: ElderOffsets = ElderOffsets()
    robot_avoidance: RobotAvoidanceParams = RobotAvoidanceParams()
    fear_rate_hz: float = Field(24.0, ge=0.0)
    gather_tolerance: float = Field(0.25, gt=0.0)
    at_destination_radius: float = Field(0.1, ge=0.0)
    at_destination_force: float = Field(0.01, ge=0.0)
    at_destination_vmax_factor: float = Field(0.01, ge=0.0)
    interested_in_robots: bool = True
    interact_with_walls: bool = False
    idle_recovery: float = Field(0.5, ge=0.0, le=1.0)
    wake_on_approach: bool = True


def sample_agent_params(
    params: SocialStatesParams, is_elder: NDArray[np.bool_], rng: np.random.Generator
) -> dict[str, FloatArray]:
    """Draw every distributed parameter for every agent.

    Draw order is fixed (declaration order of :class:`HumanParams`, one uniform per agent and
    parameter), so the same generator state gives the same crowd.

    Args:
        params: the statechart parameters.
        is_elder: ``(n,)`` which agents are elders.
        rng: the episode's crowd generator.

    Returns:
        ``name -> (n,)`` values (``vision_angle`` in degrees, as declared).
    """
    n = int(is_elder.shape[0])
    human = params.human
    elder = params.elder
    names = _dist_names()
    dists: list[Dist] = [getattr(human, name) for name in names]
    # One rng.random(n) per parameter, in declaration order (the stream of one call each);
    # then the arithmetic of truncated_normal on all of them at once, row by row the same
    # element-wise operations, so the same bits.
    u = np.empty((len(names), n))
    for i in range(len(names)):
        u[i] = rng.random(n)
    mean = np.empty((len(names), n))
    mean[:] = np.array([d.mean for d in dists])[:, None]
    elders = np.flatnonzero(is_elder)
    if elders.size:
        for i, (name, d) in enumerate(zip(names, dists, strict=True)):
            k = elder.offsets.get(name, 0.0)
            if k:
                mean[i, elders] += k * d.sigma
    sigma = np.array([d.sigma for d in dists])
    lo = np.array([-math.inf if d.lo is None else float(d.lo) for d in dists])
    hi = np.array([math.inf if d.hi is None else float(d.hi) for d in dists])
    vals = np.clip(mean, lo[:, None], hi[:, None])  # sigma 0: the mean clipped to the bounds
    rows = np.flatnonzero(sigma > 0.0)
    if rows.size:
        vals[rows] = _truncated_normal_rows(
            mean[rows], sigma[rows, None], lo[rows, None], hi[rows, None], u[rows]
        )
    out: dict[str, FloatArray] = {}
    for i, name in enumerate(names):
        if name in elder.constants:
            vals[i, is_elder] = elder.constants[name]
        out[name] = vals[i]
    return out


def _truncated_normal_rows(
    mean: FloatArray, sigma: FloatArray | float, lo: FloatArray | float, hi: FloatArray | float,
    u: FloatArray,
) -> FloatArray:
    """The inverse-CDF draws of :func:`truncated_normal`, element-wise (shapes broadcast).

    Args:
        mean: ``(p, n)`` means.
        sigma: ``(p, 1)`` standard deviations (> 0).
        lo: ``(p, 1)`` lower bounds (-inf for none).
        hi: ``(p, 1)`` upper bounds (inf for none).
        u: ``(p, n)`` uniforms in ``[0, 1)``.

    Returns:
        ``(p, n)`` samples.
    """
    a = (lo - mean) / sigma
    b = (hi - mean) / sigma
    # Work in the mirrored variable when the interval lies in the upper tail: ndtr near 1 loses
    # all precision, near 0 it does not.
    flip = a > 0.0
    a2 = np.where(flip, -b, a)
    b2 = np.where(flip, -a, b)
    fa = ndtr(a2)
    fb = ndtr(b2)
    z = ndtri(fa + u * (fb - fa))
    z = np.where(flip, -z, z)
    out: FloatArray = np.clip(mean + sigma * z, lo, hi)
    return out


@functools.cache
def _dist_names() -> tuple[str, ...]:
    """:meth:`HumanParams.dist_names` (fixed by the class)."""
    return HumanParams.dist_names()
