"""docs/plugins.md cannot rot: each example file is extracted, loaded as a plugin and checked."""

from __future__ import annotations

import re
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from arena.plugins import all_registries, load_plugins
from arena.testing import check_crowd_model, check_local_planner, check_task_mode
from tests.eval._records import make_record

GUIDE = Path(__file__).resolve().parents[1] / "docs" / "plugins.md"


def _blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", GUIDE.read_text(encoding="utf-8"), flags=re.S)


def _files() -> dict[str, str]:
    """``{file name: source}`` of the guide's example files (blocks starting ``# NAME.py``)."""
    out = {}
    for block in _blocks():
        first = block.splitlines()[0]
        if re.fullmatch(r"# \w+\.py", first):
            out[first[2:]] = block
    return out


@pytest.fixture(scope="module")
def guide_plugins(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Path]]:
    folder = tmp_path_factory.mktemp("guide")
    paths = {}
    for name, source in _files().items():
        paths[name] = folder / name
        paths[name].write_text(source, encoding="utf-8")
    before = {kind: set(reg.names()) for kind, reg in all_registries().items()}
    load_plugins([str(p) for p in paths.values()], export=False)
    yield paths
    # leave the registries as other test modules expect them
    for kind, reg in all_registries().items():
        for name in set(reg.names()) - before.get(kind, set()):
            reg._entries.pop(name)


def test_the_guide_has_one_example_per_kind() -> None:
    assert sorted(_files()) == ["my_crowd.py", "my_metric.py", "my_planner.py", "my_task.py"]


def test_every_check_snippet_of_the_guide_runs(guide_plugins: dict[str, Path]) -> None:
    """The snippets that are not example files (the checks) run as they are written."""
    snippets = [b for b in _blocks() if not re.match(r"# \w+\.py\n", b)]
    checks = [b for b in snippets if "check_" in b]
    assert len(checks) == 3
    for code in checks:
        exec(compile(code, str(GUIDE), "exec"), {})


def test_crowd_example_passes_the_crowd_model_checks(guide_plugins: dict[str, Path]) -> None:
    from arena.crowd.base import CROWD_MODELS

    check_crowd_model(lambda: CROWD_MODELS.build({"type": "polite_walker", "strength": 3.0}))


def test_planner_example_passes_the_local_planner_checks(guide_plugins: dict[str, Path]) -> None:
    from arena.nav import LOCAL_PLANNERS

    check_local_planner(lambda: LOCAL_PLANNERS.build({"type": "go_to_goal", "speed": 0.4}))


def test_task_example_passes_the_task_mode_checks(guide_plugins: dict[str, Path]) -> None:
    from arena.tasks.generator import TaskGenerator

    check_task_mode("robots", {"type": "left_to_right", "band": 0.25})
    # and it does what it says: start in the left quarter, goal in the right quarter
    from arena.robots.presets import load_robot
    from arena.tasks.config import TaskConfig

    cfg = TaskConfig.model_validate({"robots": {"type": "left_to_right", "band": 0.25}})
    gen = TaskGenerator(cfg, map_spec={"type": "empty", "width": 16.0, "height": 8.0},
                        robots=[load_robot("burger")], seed=3)
    for i in range(5):
        r = gen.episode(i).robots[0]
        assert r.start.x <= 4.0 and r.goal.x >= 12.0


def test_metric_example_on_a_known_record(guide_plugins: dict[str, Path]) -> None:
    from arena.eval.metrics import METRICS, compute_metrics

    # speeds 0, 0, 1, 1, 0.02, 0 m/s at 0.1 s steps: steps 0, 1 and 4 start below 5 cm/s
    v = np.array([0.0, 0.0, 1.0, 1.0, 0.02, 0.0])
    pose = np.stack([np.cumsum(v) * 0.1, np.zeros(6), np.zeros(6)], axis=1)
    rec = make_record(pose, np.stack([v, np.zeros(6), np.zeros(6)], axis=1))
    assert compute_metrics(rec, ["standstill_time"]) == {"standstill_time": pytest.approx(0.3)}
    assert METRICS.get("standstill_time").unit == "s"
