"""The 3-D tests' guard skips on a user's machine without the extra and fails in CI."""

from __future__ import annotations

import pytest

from tests.mujoco_kit import unavailable


def test_missing_extra_skips_here_and_fails_in_ci(monkeypatch):
    monkeypatch.delenv("ARENA_REQUIRE_GL", raising=False)
    with pytest.raises(pytest.skip.Exception, match="no GL"):
        unavailable("no GL")
    monkeypatch.setenv("ARENA_REQUIRE_GL", "1")
    with pytest.raises(pytest.fail.Exception, match=r"no GL \(ARENA_REQUIRE_GL=1: CI"):
        unavailable("no GL")
