"""Episode metrics: pure functions of an :class:`~arena.eval.record.EpisodeRecord`.

:mod:`.arena_set` holds Arena-Rosnav's 13 metrics (intended definitions), :mod:`.social` the
social-navigation set after Francis et al. (2023), :mod:`.counterfactual` how far the robot
displaced people (against the crowd replayed without it). :func:`compute_metrics` evaluates any
of them.
"""

from arena.eval.metrics import (  # noqa: F401  (registers the built-ins)
    arena_set,
    counterfactual,
    social,
    tracking,
)
from arena.eval.metrics.base import (
    METRICS,
    Metric,
    MetricParams,
    compute_metrics,
    get_metric,
    metric,
)

__all__ = ["METRICS", "Metric", "MetricParams", "compute_metrics", "get_metric", "metric"]
