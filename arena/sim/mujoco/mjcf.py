"""A :class:`~.scene.Scene3D` as MJCF text, compiled by MuJoCo (optional extra ``arena[3d]``).

The XML is the single description: :func:`compile_model` compiles exactly what :func:`to_mjcf`
writes, and ``arena maps export --format mjcf`` saves the same text.
"""

from __future__ import annotations

import math
import os
import sys
import xml.etree.ElementTree as ET
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from arena.core.errors import ConfigError
from arena.sim.mujoco.gl import INSTALL_HINT, choose_gl
from arena.sim.mujoco.scene import Body, Scene3D
from arena.sim.mujoco.terrain import HeightField

if TYPE_CHECKING:
    import mujoco

TIMESTEP = 0.01
"""s, MuJoCo's integration step in the written model (the simulator backend may override it)."""


def _num(*values: float) -> str:
    """Space-separated numbers, exact to well below a micrometre."""
    return " ".join(f"{v:.9g}" for v in values)


def yaw_quat(yaw: float) -> tuple[float, float, float, float]:
    """``(w, x, y, z)`` of a rotation by ``yaw`` (rad) about z."""
    return (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))


def _body(parent: ET.Element, body: Body) -> None:
    attrs = {"name": body.name, "pos": _num(*body.pos), "quat": _num(*yaw_quat(body.yaw))}
    if body.mocap:
        attrs["mocap"] = "true"
    el = ET.SubElement(parent, "body", attrs)
    if body.free:
        ET.SubElement(el, "freejoint", {"name": f"{body.name}/free"})
    for g in body.geoms:
        ET.SubElement(el, "geom", {"name": g.name, "type": g.type, "size": _num(*g.size),
                                   "pos": _num(*g.pos), "material": g.material})


def to_mjcf(scene: Scene3D) -> str:
    """The MJCF document of ``scene`` (UTF-8 text): materials, floor, lights and bodies."""
    p = scene.params
    root = ET.Element("mujoco", {"model": scene.name})
    ET.SubElement(root, "compiler", {"angle": "radian"})
    ET.SubElement(root, "option", {"timestep": _num(TIMESTEP)})
    visual = ET.SubElement(root, "visual")
    ET.SubElement(visual, "headlight", {"ambient": "0.3 0.3 0.3", "diffuse": "0.4 0.4 0.4"})
    ET.SubElement(visual, "global", {"offwidth": "1280", "offheight": "960"})
    asset = ET.SubElement(root, "asset")
    terrain = scene.terrain
    used = {g.material for b in scene.bodies for g in b.geoms} | {"floor"}
    if isinstance(terrain, HeightField):
        used.add(terrain.material)
        ET.SubElement(asset, "hfield", {
            "name": terrain.name, "nrow": str(terrain.nrow), "ncol": str(terrain.ncol),
            "size": _num(*terrain.size), "elevation": _num(*terrain.mjcf_elevation())})
    elif terrain is not None:
        used |= {g.material for g in terrain.geoms}
    for m in sorted(used):
        ET.SubElement(asset, "material", {"name": m, "rgba": _num(*p.rgba(m))})
    world = ET.SubElement(root, "worldbody")
    x0, y0, x1, y1 = scene.bounds
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    diffuse = _num(*[0.2 + 0.6 / max(p.lights, 1)] * 3)  # the lights add up to 0.8
    for k, direction in enumerate(p.light_directions()):
        ET.SubElement(world, "light", {
            "name": f"light/{k}", "directional": "true", "castshadow": "false",
            "pos": _num(cx, cy, 10.0), "dir": _num(*direction), "diffuse": diffuse})
    if p.floor:
        # Under a height field, whose level parts lie at z = 0, the floor drops 1 mm: the two
        # coplanar surfaces would flicker (z-fighting) and rays would hit either.
        floor_z = -1e-3 if isinstance(terrain, HeightField) else 0.0
        ET.SubElement(world, "geom", {"name": "floor", "type": "plane", "material": "floor",
                                      "pos": _num(cx, cy, floor_z),
                                      "size": _num((x1 - x0) / 2, (y1 - y0) / 2, 0.1)})
    if isinstance(terrain, HeightField):
        ET.SubElement(world, "geom", {"name": terrain.name, "type": "hfield",
                                      "hfield": terrain.name, "pos": _num(*terrain.pos),
                                      "material": terrain.material})
    elif terrain is not None:
        _body(world, terrain)
    for body in scene.bodies:
        _body(world, body)
    ET.indent(root)
    return ET.tostring(root, encoding="unicode") + "\n"


def import_mujoco() -> Any:
    """The ``mujoco`` module, or a one-line error saying how to install it.

    Without a display, offscreen rendering goes through EGL or OSMesa, whichever is installed,
    unless ``MUJOCO_GL`` says otherwise (:func:`.gl.choose_gl`); MuJoCo reads the variable on
    import.
    """
    if "mujoco" not in sys.modules:
        backend = choose_gl()
        if backend is not None:
            os.environ["MUJOCO_GL"] = backend
    try:
        import mujoco
    except ImportError as e:
        if e.name not in ("mujoco", None):  # a library MuJoCo's GL backend needs
            raise _gl_import_error(e) from None
        raise ConfigError(
            "3-D worlds need the mujoco package: pip install 'arena[3d]' (mujoco==4.0.0)"
        ) from None
    except Exception as e:  # MuJoCo loads its GL backend on import (MUJOCO_GL)
        raise _gl_import_error(e) from None
    return mujoco


def _gl_import_error(e: BaseException) -> ConfigError:
    """One line for a MuJoCo import that failed in its OpenGL backend (``MUJOCO_GL``)."""
    gl = os.environ.get("MUJOCO_GL", "")
    first = str(e).splitlines()[0] if str(e) else ""
    return ConfigError(
        f"mujoco could not load its OpenGL backend MUJOCO_GL={gl!r} ({type(e).__name__}: "
        f"{first}); unset MUJOCO_GL to let arena choose, or {INSTALL_HINT}"
    )


def compile_model(scene_or_xml: Scene3D | str) -> mujoco.MjModel:
    """The compiled ``MjModel`` of a scene (or of MJCF text)."""
    mujoco = import_mujoco()
    xml = scene_or_xml if isinstance(scene_or_xml, str) else to_mjcf(scene_or_xml)
    return mujoco.MjModel.from_xml_string(xml)


def person_ids_by_geom(model: mujoco.MjModel) -> NDArray[np.int64]:
    """``(ngeom,)`` the person id of every geom (``-1``: not a person), for segmentation.

    Person geoms are named ``person/<id>/<part>`` (see :mod:`.figures`).
    """
    mujoco = import_mujoco()
    ids = np.full(model.ngeom, -1, dtype=np.int64)
    for g in range(model.ngeom):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) or ""
        if name.startswith("person/"):
            ids[g] = int(name.split("/")[1])
    return ids
