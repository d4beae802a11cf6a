"""EpisodePrefetcher: episodes drawn in a helper process equal those drawn in-process."""

from __future__ import annotations

import time
from functools import partial
from typing import Any

import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

from arena.learn.batched import BatchedSocialNavEnv, make_generator
from arena.learn.prefetch import EpisodePrefetcher
from arena.scene.episode import Episode, episode_digest
from tests.learn.helpers import small_cfg, small_robot


def wait_for(pre: EpisodePrefetcher, indices: list[int], timeout: float = 120.0) -> None:
    """Until every episode of ``indices`` has arrived (the first ones import arena first)."""
    deadline = time.monotonic() + timeout
    while not all(pre.ready(i) for i in indices):
        assert time.monotonic() < deadline, "prefetch process too slow or stuck"
        time.sleep(0.02)


def test_prefetched_episodes_are_the_drawn_ones_and_share_their_maps() -> None:
    # A new generated map every second episode: maps travel once and episodes share them.
    cfg = small_cfg(
        "map={type: rosnav_indoor, width: 12, height: 12, resolution: 0.1}",
        "task.modules=[{type: dynamic_map, episodes_per_map: 2}]",
    )
    robot = small_robot()
    pre = EpisodePrefetcher(partial(make_generator, cfg), robot, 5, None)
    try:
        pre.request(range(5))
        assert pre.wait(timeout=120.0)  # everything asked for has arrived
        assert all(pre.ready(i) for i in range(5))
        got = [pre.take(i) for i in range(5)]
    finally:
        pre.close()
    assert pre._proc.poll() is not None  # close() ended the helper
    ref = make_generator(cfg, robot, 5, None)
    assert all(isinstance(ep, Episode) for ep in got)
    eps = [ep for ep in got if ep is not None]
    assert [episode_digest(ep) for ep in eps] == [episode_digest(ref.episode(i)) for i in range(5)]
    assert eps[0].grid is eps[1].grid and eps[2].grid is eps[3].grid
    assert eps[1].grid is not eps[2].grid
    assert all(ep.robots[0].model is robot for ep in eps)  # the caller's model, not a copy
    assert "distance" in vars(eps[0].grid)  # the distance map came computed


def test_restart_drops_the_old_generator_and_take_never_waits() -> None:
    cfg = small_cfg()
    robot = small_robot()
    pre = EpisodePrefetcher(partial(make_generator, cfg), robot, 1, None)
    try:
        pre.request(range(4))
        pre.restart(2, None)  # before the helper had a chance: its seed-1 draws are dropped
        pre.request([0, 1])
        wait_for(pre, [0, 1])
        assert not pre.ready(2) and pre.take(2) is None  # never asked for: the caller draws it
        got = [pre.take(0), pre.take(1)]
        assert pre.take(0) is None  # taken once
    finally:
        pre.close()
    ref = make_generator(cfg, robot, 2, None)
    assert [episode_digest(ep) for ep in got if ep is not None] == [
        episode_digest(ref.episode(i)) for i in range(2)
    ]


def rollout(env: BatchedSocialNavEnv, steps: int) -> list[object]:
    rng = np.random.default_rng(3)
    out: list[object] = [env.reset(seed=11)[0]]
    for k in range(steps):
        if k == 20:
            env.set_stage(2)  # the curriculum moves: episodes from the new stage on
        if k == 45:
            out.append(env.reset(seed=12)[0])  # a new seed restarts the episode sequence
        a = rng.integers(env.single_action_space.n, size=env.num_envs)
        obs, rew, term, trunc, info = env.step(a)
        out += [obs, rew, term, trunc, info["episode_index"], info["time"]]
    return out


def test_batched_env_with_prefetch_steps_exactly_as_without() -> None:
    mode = AutoresetMode.SAME_STEP  # training's mode (NEXT_STEP draws through the same code)
    cfg = small_cfg(
        "learning.env.max_steps=8",  # many restarts
        "task.modules=[{type: staged, curriculum: default}]",
    )
    runs = []
    for prefetch in (0, 2):
        env = BatchedSocialNavEnv(
            cfg, robot=small_robot(), num_envs=3, autoreset_mode=mode, prefetch=prefetch
        )
        if prefetch:  # the helper delivers most episodes (not only the env's own draws)
            env.reset(seed=11)
            assert env.wait_prefetch(timeout=120.0)
            assert env._prefetcher is not None and len(env._prefetcher._ready) == 3 * prefetch
        else:
            assert env.wait_prefetch(timeout=0.0)  # nothing to wait for
        runs.append(rollout(env, 70))
        if prefetch:
            assert env._prefetcher is not None
            proc = env._prefetcher._proc
            env.close()
            assert proc.poll() is not None
    a, b = runs
    assert len(a) == len(b)
    for x, y in zip(a, b, strict=True):
        if isinstance(x, dict):
            assert x.keys() == y.keys()  # type: ignore[union-attr]
            for k in x:
                np.testing.assert_array_equal(x[k], y[k])  # type: ignore[index]
        else:
            np.testing.assert_array_equal(x, y)  # type: ignore[arg-type]
    assert max(int(np.max(x)) for x in a[1:] if isinstance(x, np.ndarray) and x.dtype == np.int64
               ) >= 3 * 4  # several restarts per world


def test_a_draw_that_fails_in_the_helper_raises_here() -> None:
    cfg = small_cfg("task.robots.min_goal_distance=50.0")  # no such pair on an 8 m map
    pre = EpisodePrefetcher(partial(make_generator, cfg), small_robot(), 0, None)
    try:
        pre.request([0])
        deadline = time.monotonic() + 120.0
        while 0 not in pre._failed:  # the helper reports the failure instead of dying
            assert time.monotonic() < deadline
            pre.pump()
            time.sleep(0.02)
        assert pre.take(0) is None
        assert pre._proc.poll() is None
    finally:
        pre.close()
    with pytest.raises(Exception) as plain:
        BatchedSocialNavEnv(cfg, robot=small_robot(), num_envs=1).reset(seed=0)
    env = BatchedSocialNavEnv(cfg, robot=small_robot(), num_envs=1, prefetch=1)
    try:
        with pytest.raises(type(plain.value), match="no start/goal pair"):
            env.reset(seed=0)
    finally:
        env.close()


def test_a_lost_helper_leaves_the_drawing_to_the_env() -> None:
    # Killing the helper mid-run (as an out-of-memory killer would) costs a warning, not the
    # run: the env draws the remaining episodes itself, and the rollout is unchanged.
    import warnings

    cfg = small_cfg("learning.env.max_steps=6")  # a restart every few steps
    runs = []
    for prefetch in (0, 1):
        env = BatchedSocialNavEnv(cfg, robot=small_robot(), num_envs=2, prefetch=prefetch)
        rng = np.random.default_rng(4)
        out: list[Any] = [env.reset(seed=3)[0]]
        if prefetch:
            assert env.wait_prefetch(timeout=120.0)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            for k in range(40):
                if k == 10 and env._prefetcher is not None:
                    env._prefetcher._proc.kill()
                    env._prefetcher._proc.wait()
                obs, rew, _, _, info = env.step(rng.integers(env.single_action_space.n, size=2))
                out += [obs, rew, info["episode_index"]]
        lost = [w for w in caught if "prefetch process ended" in str(w.message)]
        if prefetch:
            assert env._prefetcher is not None and env._prefetcher.lost
            assert len(lost) == 1 and lost[0].category is RuntimeWarning
        else:
            assert not lost
        env.close()
        runs.append(out)
    assert len(runs[0]) == len(runs[1])
    for x, y in zip(*runs, strict=True):
        if isinstance(x, dict):
            assert x.keys() == y.keys()
            for key in x:
                np.testing.assert_array_equal(x[key], y[key])
        else:
            np.testing.assert_array_equal(x, y)
    first, last = runs[1][3 * 10 + 3], runs[1][-1]  # episode indices at k = 10 and at the end
    assert (last > first).all()  # both worlds restarted after the helper died
