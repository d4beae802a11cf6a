"""Headless GL: EGL or OSMesa picked by itself, a one-line error saying what to install."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from arena.core.errors import ConfigError
from arena.sim.mujoco.gl import INSTALL_HINT, choose_gl, gl_error, open_context


def libs(*found: str):
    return lambda name: f"lib{name}.so.1" if name in found else None


@pytest.mark.parametrize(("env", "found", "want"), [
    ({}, ("EGL", "OSMesa"), "egl"),
    ({}, ("OSMesa",), "osmesa"),
    ({}, (), "egl"),  # nothing found: EGL, whose context error then says what to install
    ({"MUJOCO_GL": "osmesa"}, ("EGL",), None),  # the user's choice wins
    ({"DISPLAY": ":0"}, ("EGL",), None),  # a display: MuJoCo's default (GLFW)
    ({"WAYLAND_DISPLAY": "wayland-0"}, ("EGL",), None),
])
def test_choose_gl(env, found, want):
    assert choose_gl(env, libs(*found)) == want


class Broken:
    def __init__(self, width: int, height: int) -> None:
        raise RuntimeError("Cannot initialize a EGL device display.\nmore detail")


class Fine:
    def __init__(self, width: int, height: int) -> None:
        self.size = (width, height)
        self.current = False

    def make_current(self) -> None:
        self.current = True


def test_open_context_failure_is_one_line_with_what_to_install(monkeypatch):
    monkeypatch.setenv("MUJOCO_GL", "egl")
    for fake in (SimpleNamespace(GLContext=Broken), SimpleNamespace()):
        with pytest.raises(ConfigError) as e:
            open_context(fake, 320, 240)
        msg = str(e.value)
        assert "\n" not in msg
        assert msg.startswith("no working OpenGL for MuJoCo's offscreen rendering "
                              "(MUJOCO_GL='egl': ")
        assert msg.endswith(INSTALL_HINT)
        assert "tools/install_gl.sh" in msg and "libegl1" in msg
    with pytest.raises(ConfigError, match=r": Cannot initialize a EGL device display\.\); run"):
        open_context(SimpleNamespace(GLContext=Broken), 1, 1)  # its first line only
    ctx = open_context(SimpleNamespace(GLContext=Fine), 320, 240)
    assert ctx.size == (320, 240) and ctx.current


def test_glfw_without_a_display_says_to_set_mujoco_gl(monkeypatch):
    # mujoco imported before arena: no MUJOCO_GL, no display -> GLFW, which cannot work here
    for var in ("MUJOCO_GL", "DISPLAY", "WAYLAND_DISPLAY"):
        monkeypatch.delenv(var, raising=False)
    msg = str(gl_error(RuntimeError("an OpenGL platform library has not been loaded\nmore")))
    assert "\n" not in msg
    assert "MUJOCO_GL='': an OpenGL platform library has not been loaded);" in msg
    assert "set MUJOCO_GL=egl (or osmesa) before importing it" in msg and INSTALL_HINT in msg
    monkeypatch.setenv("MUJOCO_GL", "egl")
    assert "before importing it" not in str(gl_error(RuntimeError("x")))


def test_a_mujoco_gl_that_cannot_load_is_one_line_naming_it():
    """MuJoCo loads its GL backend on import: a bad or missing one is not a traceback."""
    import os
    import subprocess
    import sys

    from tests.mujoco_kit import require_mujoco

    require_mujoco(module=False)  # a skip on a user's machine without arena[3d]; CI fails
    code = ("from arena.core.errors import ConfigError\n"
            "from arena.sim.mujoco.mjcf import import_mujoco\n"
            "try:\n    import_mujoco()\nexcept ConfigError as e:\n    print(e)\n")
    env = {**os.environ, "MUJOCO_GL": "no_such_backend"}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                         text=True, check=True, timeout=120).stdout.strip()
    assert "\n" not in out
    assert "MUJOCO_GL='no_such_backend'" in out and "unset MUJOCO_GL" in out
