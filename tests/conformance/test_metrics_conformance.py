"""Every registered metric: a float (finite or NaN), deterministic, record untouched, documented."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest

from arena.eval.metrics import METRICS, MetricParams, get_metric
from tests.eval._records import make_record, straight


def _records():
    import dataclasses

    rng = np.random.default_rng(0)
    n = 40
    pose = np.cumsum(rng.normal(0, 0.1, (n, 3)), axis=0)
    vel = rng.normal(0, 0.5, (n, 3))
    peds = [(j, i, *rng.normal(0, 1.5, 2), *rng.normal(0, 1, 2), rng.uniform(-3, 3), 0.25)
            for j in range(n) for i in range(4)]
    crowd = make_record(pose, vel, peds=peds, outcome="collision",
                        min_range=rng.uniform(0.3, 4, n))
    cf = crowd.ped_position + rng.normal(0, 0.2, crowd.ped_position.shape)
    cf[::7] = np.nan  # people the replay does not have
    return [
        straight(),
        dataclasses.replace(crowd, ped_cf_position=cf),
        straight(n=1),
        straight(n=2, collision=[1, 0]),
        make_record(pose, vel, peds=peds, outcome="collision", min_range=rng.uniform(0.3, 4, n)),
        make_record(np.zeros((5, 3)), outcome="stuck", goal=[1.0, 0, 0]),
    ]


@pytest.mark.parametrize("name", METRICS.names())
def test_metric(name):
    metric = get_metric(name)
    assert metric.unit and metric.description and METRICS.entry(name).summary
    for rec in _records():
        before = copy.deepcopy(rec)
        value = metric(rec, MetricParams())
        assert isinstance(value, float)
        assert math.isfinite(value) or math.isnan(value), (name, value)
        again = metric(rec)
        assert value == again or (math.isnan(value) and math.isnan(again))
        for field in ("time", "pose", "velocity", "min_range", "ped_position", "ped_velocity"):
            np.testing.assert_array_equal(getattr(rec, field), getattr(before, field))
