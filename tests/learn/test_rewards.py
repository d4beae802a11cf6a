"""Reward terms against hand-computed values; the reward function; the packaged files."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from arena.learn.rewards import (
    REWARD_TERMS,
    DoneReason,
    RewardFunction,
    RewardInput,
    SingleRewardInput,
    build_term,
    packaged_reward,
)


def make_input(**kw) -> RewardInput:
    """Two worlds, three pedestrian slots; nothing happening unless ``kw`` says so."""
    n, m = 2, 3
    base = {
        "action": np.zeros((n, 3)),
        "prev_action": np.zeros((n, 3)),
        "goal_distance": np.full(n, 5.0),
        "prev_goal_distance": np.full(n, 5.0),
        "goal_jump": np.zeros(n),
        "goal_radius": np.full(n, 0.3),
        "goal_reached": np.zeros(n, bool),
        "min_range": np.full(n, 10.0),
        "robot_radius": np.full(n, 0.3),
        "safe_dist": np.full(n, 0.8),
        "collision": np.zeros(n, bool),
        "heading": np.zeros(n),
        "prev_heading": np.zeros(n),
        "dt": np.full(n, 0.1),
        "step": np.ones(n, np.int64),
        "max_steps": np.full(n, 500, np.int64),
        "ped_distance": np.full((n, m), 10.0),
        "ped_kind": np.zeros((n, m), np.int64),
        "ped_mask": np.ones((n, m), bool),
    }
    base.update({k: np.asarray(v) for k, v in kw.items()})
    return RewardInput(**base)


def term(name, **params):
    return build_term(name, **params)


def test_goal_reached():
    res = term("goal_reached")(make_input(goal_reached=[True, False]))
    np.testing.assert_array_equal(res.reward, [15.0, 0.0])
    np.testing.assert_array_equal(res.done, [True, False])
    assert res.reason is DoneReason.SUCCESS


def test_collision_from_contacts_and_optionally_laser():
    inp = make_input(collision=[False, True], min_range=[0.32, 5.0])
    res = term("collision")(inp)
    np.testing.assert_array_equal(res.reward, [0.0, -10.0])
    assert res.reason is DoneReason.COLLISION
    res = term("collision", from_laser=True)(inp)  # 0.32 <= 0.3 + 0.05
    np.testing.assert_array_equal(res.reward, [-10.0, -10.0])


def test_safe_distance():
    res = term("safe_distance")(make_input(min_range=[0.8, 0.81]))
    np.testing.assert_array_equal(res.reward, [-0.15, 0.0])


def test_no_movement():
    res = term("no_movement")(make_input(action=[[0.1, 0, 1.0], [-0.11, 0, 0]]))
    np.testing.assert_array_equal(res.reward, [-0.01, 0.0])


def test_approach_goal_asymmetric_and_skipped_on_goal_jump():
    inp = make_input(prev_goal_distance=[5.0, 5.0], goal_distance=[4.0, 5.5])
    np.testing.assert_allclose(term("approach_goal")(inp).reward, [0.3 * 1.0, 0.5 * -0.5])
    jumped = make_input(prev_goal_distance=[5.0, 5.0], goal_distance=[4.0, 4.0],
                        goal_jump=[2.5, 2.4])
    np.testing.assert_allclose(term("approach_goal")(jumped).reward, [0.0, 0.3])


def test_distance_travelled():
    res = term("distance_travelled")(make_input(action=[[1.0, 0, 2.0], [-0.5, 0, -1.0]]))
    np.testing.assert_allclose(res.reward, [-(1.0 + 0.002) * 0.005, -(0.5 + 0.001) * 0.005])


def test_reverse_drive_threshold():
    inp = make_input(action=[[-0.6, 0, 0], [-0.4, 0, 0]])
    np.testing.assert_allclose(term("reverse_drive")(inp).reward, [-0.01, -0.01])
    np.testing.assert_allclose(
        term("reverse_drive", reward=-0.1, threshold=-0.5)(inp).reward, [-0.1, 0.0]
    )


def test_abrupt_velocity_change():
    inp = make_input(action=[[1.0, 0, 2.0], [0, 0, 0]], prev_action=[[0.0, 0, 0.0], [0, 0, 0]])
    res = term("abrupt_velocity_change")(inp)
    np.testing.assert_allclose(res.reward, [-(1.0 / 100 * 0.3 + 16.0 / 100 * 0.07), 0.0])


def test_two_factor_velocity_difference():
    inp = make_input(action=[[1.0, 0, 2.0], [0, 0, 0]], prev_action=[[0.5, 0, -1.0], [0, 0, 0]])
    res = term("two_factor_velocity_difference")(inp)
    np.testing.assert_allclose(res.reward, [-(0.002 * 0.25 + 0.005 * 9.0), 0.0])


def test_ped_type_terms_only_see_their_type():
    d = [[1.0, 0.3, 5.0], [1.0, 0.3, 5.0]]
    kinds = [[1, 0, 0], [0, 0, 1]]  # world 0: elder at 1.0 m; world 1: elder at 5.0 m
    inp = make_input(ped_distance=d, ped_kind=kinds, action=[[0.4, 0, 0], [0.4, 0, 0]])
    np.testing.assert_allclose(term("ped_type_safety_distance")(inp).reward, [-0.25, 0.0])
    np.testing.assert_allclose(term("ped_type_vel_constraint")(inp).reward, [-0.05 * 0.4, 0.0])
    np.testing.assert_allclose(term("ped_type_collision")(inp).reward, [0.0, 0.0])
    close = make_input(ped_distance=[[0.35, 9, 9], [0.36, 9, 9]], ped_kind=[[1, 0, 0], [1, 0, 0]])
    np.testing.assert_allclose(term("ped_type_collision")(close).reward, [-10.0, 0.0])
    masked = dataclasses.replace(close, ped_mask=np.zeros((2, 3), bool))
    np.testing.assert_allclose(term("ped_type_collision")(masked).reward, [0.0, 0.0])


def test_angular_vel_constraint_wraps_heading():
    inp = make_input(heading=[math.pi - 0.05, 0.01], prev_heading=[-math.pi + 0.05, 0.0])
    np.testing.assert_allclose(term("angular_vel_constraint")(inp).reward, [0.0, 0.0])
    res = term("angular_vel_constraint", threshold=0.5)(inp)  # |Δψ| = 0.1 → 1.0 rad/s
    np.testing.assert_allclose(res.reward, [-0.05 * 1.0, 0.0], atol=1e-12)


def test_max_steps_exceeded():
    res = term("max_steps_exceeded")(make_input(step=[500, 499]))
    np.testing.assert_array_equal(res.reward, [-10.0, 0.0])
    assert res.reason is DoneReason.STEP_LIMIT


def test_reward_function_sums_terms_and_reports_breakdown():
    fn = RewardFunction({"goal_reached": {}, "safe_distance": {"weight": 2.0}, "collision": {}})
    out = fn(make_input(goal_reached=[True, False], min_range=[5.0, 0.5], collision=[False, True]))
    np.testing.assert_allclose(out.terms["safe_distance"], [0.0, -0.3])
    np.testing.assert_allclose(out.total, [15.0, -10.3])
    assert out.reasons() == [DoneReason.SUCCESS, DoneReason.COLLISION]
    np.testing.assert_array_equal(out.done, [True, True])


def test_on_safe_dist_violation_false_mutes_the_term_during_breach():
    fn = RewardFunction({"no_movement": {"_on_safe_dist_violation": False}})
    out = fn(make_input(min_range=[0.5, 5.0]))
    np.testing.assert_allclose(out.total, [0.0, -0.01])


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        ("default", {"goal_reached": {"reward": 15}, "collision": {"reward": -20},
                     "approach_goal": {"pos_factor": 0.5, "neg_factor": 0.8}}),
        ("base_semantic", {"goal_reached": {"reward": 20},
                           "two_factor_velocity_difference": {"alpha": 1e-5, "beta": 5e-4},
                           "ped_type_safety_distance": {"type": 1, "reward": -0.1,
                                                        "distance": 1.25}}),
        ("rule_13", {"collision": {"reward": -10}, "no_movement": {"reward": -0.01},
                     "abrupt_velocity_change": {"vel_factors": {"0": 0.3, "1": 0.07, "2": 0.07}}}),
    ],
)
def test_packaged_files_hold_the_spec_values(name, expected):
    data = packaged_reward(name)
    for key, params in expected.items():
        assert data[key] == params
    RewardFunction(name)  # every file builds


# -- conformance: every registered term ---------------------------------------------------------
@pytest.mark.parametrize("name", REWARD_TERMS.names())
def test_reward_term_conformance(name):
    rng = np.random.default_rng(0)
    n, m = 5, 4
    inp = make_input(
        action=rng.uniform(-1, 1, (n, 3)), prev_action=rng.uniform(-1, 1, (n, 3)),
        goal_distance=rng.uniform(0, 5, n), prev_goal_distance=rng.uniform(0, 5, n),
        goal_jump=rng.uniform(0, 3, n), goal_radius=np.full(n, 0.3),
        goal_reached=rng.random(n) < 0.5, min_range=rng.uniform(0, 3, n),
        robot_radius=np.full(n, 0.3), safe_dist=np.full(n, 0.8), collision=rng.random(n) < 0.5,
        heading=rng.uniform(-3, 3, n), prev_heading=rng.uniform(-3, 3, n), dt=np.full(n, 0.1),
        step=rng.integers(0, 10, n), max_steps=np.full(n, 5),
        ped_distance=rng.uniform(0, 3, (n, m)),
        ped_kind=rng.integers(0, 3, (n, m)), ped_mask=rng.random((n, m)) < 0.7,
    )
    before = {f.name: getattr(inp, f.name).copy() for f in dataclasses.fields(inp)}
    entry = REWARD_TERMS.entry(name)
    assert entry.params_model is not None, "every term declares Params with Arena's defaults"
    t = build_term(name)
    res = t(inp)
    assert res.reward.shape == (n,) and res.reward.dtype == np.float64
    assert np.all(np.isfinite(res.reward))
    assert res.done.shape == (n,) and res.done.dtype == bool
    assert not res.done.any() or res.reason is not DoneReason.NONE
    for f, v in before.items():  # inputs not mutated
        np.testing.assert_array_equal(getattr(inp, f), v)
    # world-wise: evaluating one world alone gives that world's value
    one = RewardInput(**{f: v[2:3] for f, v in before.items()})
    np.testing.assert_allclose(t(one).reward, res.reward[2:3])
    # no pedestrians at all is fine
    empty = dataclasses.replace(
        inp, ped_distance=np.zeros((n, 0)), ped_kind=np.zeros((n, 0), np.int64),
        ped_mask=np.zeros((n, 0), bool),
    )
    assert np.all(np.isfinite(t(empty).reward))


def test_function_shortcuts_match_the_plain_formula():
    """Weights, masking and reasons as ``where(active, w · r, 0)``; shares are fresh arrays."""
    spec = {
        "goal_reached": {"reward": 15, "weight": 0.5, "_on_safe_dist_violation": False},
        "collision": {"reward": -10, "from_laser": True},
        "safe_distance": {"weight": -1.5},
        "approach_goal": {"_on_safe_dist_violation": False},
        "max_steps_exceeded": {"weight": 2.0},
    }
    fn = RewardFunction(spec)
    rng = np.random.default_rng(0)
    for _ in range(50):
        inp = make_input(
            goal_distance=rng.random(2) * 5,
            goal_reached=rng.random(2) < 0.5,
            min_range=rng.random(2) * 1.5,
            collision=rng.random(2) < 0.3,
            step=rng.integers(495, 505, 2),
        )
        out = fn(inp)
        calm = ~(inp.min_range <= inp.safe_dist)
        total = np.zeros(2)
        done = np.zeros(2, bool)
        reason = np.zeros(2, np.int64)
        for name, term in fn.terms.items():
            res = term(inp)
            active = np.ones(2, bool) if fn.on_violation[name] else calm
            r = np.where(active, fn.weights[name] * res.reward, 0.0)
            assert out.terms[name].tobytes() == r.tobytes()
            assert out.terms[name] is not res.reward
            total += r
            fired = res.done & active
            done |= fired
            reason = np.where(fired, np.maximum(reason, int(res.reason)), reason)
        assert out.total.tobytes() == total.tobytes()
        assert np.array_equal(out.done, done)
        assert np.array_equal(out.reason, reason)


@pytest.mark.parametrize("spec", ["default", "rule_13", "rlca"])
def test_one_world_matches_each_world_of_a_batch(spec):
    """The scalar accumulation for N = 1 gives the bits of the batched arrays, world by world."""
    fn = RewardFunction(spec)
    rng = np.random.default_rng(1)
    for _ in range(50):
        batch = make_input(
            action=rng.normal(size=(2, 3)),
            goal_distance=rng.random(2) * 5,
            goal_reached=rng.random(2) < 0.3,
            min_range=rng.random(2) * 1.5,
            collision=rng.random(2) < 0.3,
            step=rng.integers(495, 505, 2),
            ped_distance=rng.random((2, 3)) * 3,
            ped_kind=rng.integers(0, 3, (2, 3)),
        )
        out = fn(batch)
        for w in range(2):
            one = dataclasses.replace(
                batch, **{f.name: getattr(batch, f.name)[w : w + 1]
                          for f in dataclasses.fields(batch)}
            )
            single = fn(one)
            assert single.total.tobytes() == out.total[w : w + 1].tobytes()
            assert single.done.dtype == bool
            assert single.reason.dtype == np.int64
            assert single.done.tolist() == out.done[w : w + 1].tolist()
            assert single.reason.tolist() == out.reason[w : w + 1].tolist()
            for name, share in single.terms.items():
                assert share.tobytes() == out.terms[name][w : w + 1].tobytes()


def _single_of(batch: RewardInput, w: int) -> SingleRewardInput:
    """World ``w`` of ``batch`` as the scalar input of :meth:`RewardFunction.single`."""
    one = dataclasses.replace(
        batch, **{f.name: getattr(batch, f.name)[w : w + 1] for f in dataclasses.fields(batch)}
    )
    a = batch.action[w].tolist()
    p = batch.prev_action[w].tolist()
    scalars = {
        f.name: getattr(batch, f.name)[w].item()
        for f in dataclasses.fields(SingleRewardInput)
        if f.name not in ("action", "prev_action", "batched")
    }
    return SingleRewardInput(
        action=(a[0], a[1], a[2]), prev_action=(p[0], p[1], p[2]), batched=lambda: one,
        **scalars,
    )


def _random_batch(rng: np.random.Generator, n: int = 2) -> RewardInput:
    """Random inputs (``n``: :func:`make_input`'s two worlds) with exact zeros, ties, signs."""
    action = rng.choice([-1.0, -0.5, -0.0, 0.0, 0.05, 0.3, 1.7], (n, 3)) + rng.normal(
        scale=rng.choice([0.0, 1.0]), size=(n, 3)
    )
    d = rng.random(n) * 5
    return make_input(
        action=action, prev_action=rng.normal(size=(n, 3)),
        goal_distance=d, prev_goal_distance=np.where(rng.random(n) < 0.3, d, rng.random(n) * 5),
        goal_jump=rng.choice([0.0, 1.0, 2.5, 3.0], n), goal_reached=rng.random(n) < 0.3,
        min_range=rng.choice([0.3, 0.35, 0.8, 1.2], n) * rng.choice([1.0, 0.9], n),
        collision=rng.random(n) < 0.3, heading=rng.uniform(-4, 4, n),
        prev_heading=rng.uniform(-4, 4, n), step=rng.integers(495, 505, n),
        ped_distance=rng.random((n, 3)) * 3, ped_kind=rng.integers(0, 3, (n, 3)),
    )


SCALAR_TERMS = [n for n in REWARD_TERMS.names() if hasattr(build_term(n), "single")]


def test_most_terms_have_a_scalar_form():
    """Terms without ``single`` (numpy powers/sums, per-pedestrian arrays) use the N = 1 arrays."""
    assert set(REWARD_TERMS.names()) - set(SCALAR_TERMS) == {
        "abrupt_velocity_change", "angular_vel_constraint", "ped_type_safety_distance",
        "ped_type_collision", "ped_type_vel_constraint",
    }


@pytest.mark.parametrize("name", SCALAR_TERMS)
def test_single_method_matches_the_batched_term_bit_for_bit(name):
    """A term's scalar ``single`` returns the bits, done flag and reason of ``__call__``."""
    t = build_term(name)
    variants = [t]
    if name == "collision":
        variants.append(build_term(name, from_laser=True))
    if name == "reverse_drive":
        variants.append(build_term(name, threshold=-0.5))
    rng = np.random.default_rng(7)
    for term_ in variants:
        for _ in range(150):
            batch = _random_batch(rng)
            res = term_(batch)
            for w in range(batch.n):
                r, done, reason = term_.single(_single_of(batch, w))
                assert type(r) is float and type(done) is bool
                assert np.array([r]).tobytes() == res.reward[w : w + 1].tobytes()
                assert done == bool(res.done[w])
                assert reason is res.reason


@pytest.mark.parametrize(
    "spec",
    [
        "default", "rule_13", "rlca", "base_semantic",
        {
            "goal_reached": {"reward": 15, "weight": 0.5, "_on_safe_dist_violation": False},
            "collision": {"reward": -10, "from_laser": True},
            "safe_distance": {"weight": -1.5},
            "approach_goal": {"_on_safe_dist_violation": False},
            "ped_type_vel_constraint": {"_on_safe_dist_violation": False, "weight": 3.0},
            "angular_vel_constraint": {"threshold": 0.5},
            "rotation_penalty": {},
            "no_movement": {},
            "distance_travelled": {},
            "max_steps_exceeded": {"weight": 2.0},
        },
    ],
)
def test_function_single_matches_the_batched_call_bit_for_bit(spec):
    """:meth:`RewardFunction.single` (scalar terms + fallbacks) equals ``__call__`` on N = 1."""
    fn = RewardFunction(spec)
    rng = np.random.default_rng(3)
    for _ in range(40):
        batch = _random_batch(rng)
        for w in range(batch.n):
            inp = _single_of(batch, w)
            ref = fn(inp.batched())
            out = fn.single(inp)
            assert out.total.tobytes() == ref.total.tobytes()
            assert out.done.dtype == bool and out.done.tolist() == ref.done.tolist()
            assert out.reason.dtype == np.int64 and out.reason.tolist() == ref.reason.tolist()
            assert list(out.terms) == list(ref.terms)
            for name, share in out.terms.items():
                assert share.tobytes() == ref.terms[name].tobytes(), name
