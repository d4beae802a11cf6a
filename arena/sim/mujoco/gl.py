"""Headless OpenGL for MuJoCo's offscreen rendering: pick EGL or OSMesa, open a context.

MuJoCo reads ``MUJOCO_GL`` once, when it is imported (``egl``: GPU or Mesa drivers through
EGL; ``osmesa``: Mesa's pure software renderer; unset: GLFW, which needs a display).
:func:`choose_gl` decides it before that import (``import_mujoco`` calls it); a user's own
``MUJOCO_GL`` always wins. :func:`open_context` turns any failure to create a context into one
line saying what to install.
"""

from __future__ import annotations

import ctypes.util
import os
from collections.abc import Callable, Mapping
from typing import Any

from arena.core.errors import ConfigError

INSTALL_HINT = (
    "run tools/install_gl.sh (Debian/Ubuntu: apt-get install libegl1 libopengl0 libegl-mesa0 "
    "libgl1-mesa-dri; or libosmesa6 with MUJOCO_GL=osmesa)"
)
"""What to install for headless rendering (what ``tools/install_gl.sh`` installs)."""


def choose_gl(
    environ: Mapping[str, str] | None = None,
    find_library: Callable[[str], str | None] = ctypes.util.find_library,
) -> str | None:
    """The ``MUJOCO_GL`` to set before importing MuJoCo, or ``None`` to leave it alone.

    ``None`` when the user set ``MUJOCO_GL`` or there is a display (MuJoCo then uses GLFW);
    otherwise ``egl`` when the EGL library is found, else ``osmesa`` when OSMesa is, else
    ``egl`` (whose context then fails with :func:`open_context`'s install hint rather than
    GLFW failing for want of a display).
    """
    env = os.environ if environ is None else environ
    if env.get("MUJOCO_GL") or env.get("DISPLAY") or env.get("WAYLAND_DISPLAY"):
        return None
    if find_library("EGL"):
        return "egl"
    if find_library("OSMesa"):
        return "osmesa"
    return "egl"


def open_context(mujoco: Any, width: int, height: int) -> Any:
    """A current offscreen GL context of at least ``width`` × ``height`` px.

    Raises:
        ConfigError: no working OpenGL (missing libraries, no device, a bad ``MUJOCO_GL``).
    """
    try:
        cls = getattr(mujoco, "GLContext", None)
        if cls is None:
            raise ImportError("mujoco offers no GLContext")
        ctx = cls(width, height)
        ctx.make_current()
    except Exception as e:  # GL fails in many ways (ImportError, OSError, RuntimeError, GLError)
        raise gl_error(e) from None
    return ctx


def gl_error(cause: BaseException) -> ConfigError:
    """The one-line error for a failed offscreen GL context (``cause``: what failed).

    Names the ``MUJOCO_GL`` in use and what to install; without ``MUJOCO_GL`` and without a
    display MuJoCo fell back to GLFW, which happens when it was imported before
    :func:`~arena.sim.mujoco.mjcf.import_mujoco` could choose a headless GL.
    """
    backend = os.environ.get("MUJOCO_GL", "")
    first = (str(cause).strip().splitlines() or [type(cause).__name__])[0]
    hint = INSTALL_HINT
    if not backend and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        hint = ("mujoco was imported before arena chose a headless GL and uses GLFW, which "
                "needs a display: set MUJOCO_GL=egl (or osmesa) before importing it; "
                + INSTALL_HINT)
    return ConfigError(
        f"no working OpenGL for MuJoCo's offscreen rendering (MUJOCO_GL={backend!r}: "
        f"{first}); {hint}"
    )
