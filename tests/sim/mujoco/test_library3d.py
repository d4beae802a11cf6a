"""The obstacle library's 3-D data: every model has it, and a bad entry is a one-line error."""

from __future__ import annotations

from pathlib import Path

import pytest

import arena.maps.obstacles as lib
from arena.core.errors import ConfigError
from arena.sim.mujoco.shapes import BUILDERS


def test_every_library_model_has_a_known_shape3d() -> None:
    kinds = {name: m.shape3d.kind for name, m in lib.obstacle_models().items() if m.shape3d}
    assert set(kinds) == set(lib.obstacle_models())
    assert set(kinds.values()) == set(lib.SHAPE3D_KINDS) == set(BUILDERS)


def test_unknown_shape3d_kind_names_file_and_field(monkeypatch: pytest.MonkeyPatch,
                                                   tmp_path: Path) -> None:
    bad = tmp_path / "models.yaml"
    bad.write_text("sofa: {footprint: {type: box, length: 2, width: 1}, height: 0.8, "
                   "shape3d: {kind: couch}}\n")
    monkeypatch.setattr(lib, "LIBRARY", bad)
    lib.obstacle_models.cache_clear()
    try:
        with pytest.raises(ConfigError) as err:
            lib.obstacle_models()
    finally:
        lib.obstacle_models.cache_clear()
    text = str(err.value)
    assert "\n" not in text and str(bad) in text and "sofa.shape3d.kind" in text
