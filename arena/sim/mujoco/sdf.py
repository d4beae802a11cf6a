"""A :class:`~.scene.Scene3D` as a Gazebo SDF 1.6 world (Gazebo classic 9+ and Gazebo Sim).

Walls and obstacles become static models of box/cylinder/sphere links with materials; people
with waypoint routes become ``<actor>`` elements walking a ``<script>`` trajectory (Gazebo's
stock ``walk.dae`` skin). Robots are not written: Gazebo spawns them from their own URDF/SDF.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from arena.sim.mujoco.scene import Body, Geom, Scene3D
from arena.sim.mujoco.terrain import HeightField, terrain_boxes

SDF_VERSION = "1.6"
ACTOR_SKIN = "walk.dae"
"""Gazebo's stock walking-person mesh (in its media path), used for every actor."""


def _num(*values: float) -> str:
    return " ".join(f"{v:.9g}" for v in values)


def sdf_name(name: str) -> str:
    """SDF scopes names with ``::``; slashes of the scene's names become underscores."""
    return name.replace("/", "_")


def _text(parent: ET.Element, tag: str, text: str) -> ET.Element:
    el = ET.SubElement(parent, tag)
    el.text = text
    return el


def _geometry(parent: ET.Element, g: Geom) -> None:
    geometry = ET.SubElement(parent, "geometry")
    if g.type == "box":
        _text(ET.SubElement(geometry, "box"), "size", _num(*(2 * s for s in g.size)))
    elif g.type == "cylinder":
        cyl = ET.SubElement(geometry, "cylinder")
        _text(cyl, "radius", _num(g.size[0]))
        _text(cyl, "length", _num(2 * g.size[1]))
    elif g.type == "sphere":
        _text(ET.SubElement(geometry, "sphere"), "radius", _num(g.size[0]))
    else:  # the builders give static bodies only the shapes SDF 1.6 has
        raise ValueError(f"SDF 1.6 has no {g.type} geometry (geom {g.name!r})")


def _model(world: ET.Element, body: Body, scene: Scene3D) -> None:
    model = ET.SubElement(world, "model", {"name": sdf_name(body.name)})
    _text(model, "static", "true")
    _text(model, "pose", _num(*body.pos, 0.0, 0.0, body.yaw))
    link = ET.SubElement(model, "link", {"name": "link"})
    for g in body.geoms:
        local = sdf_name(g.name.removeprefix(body.name + "/"))
        col = ET.SubElement(link, "collision", {"name": f"{local}_collision"})
        _text(col, "pose", _num(*g.pos, 0.0, 0.0, 0.0))
        _geometry(col, g)
        vis = ET.SubElement(link, "visual", {"name": f"{local}_visual"})
        _text(vis, "pose", _num(*g.pos, 0.0, 0.0, 0.0))
        _geometry(vis, g)
        material = ET.SubElement(vis, "material")
        rgba = _num(*scene.params.rgba(g.material))
        _text(material, "ambient", rgba)
        _text(material, "diffuse", rgba)


def _actor(world: ET.Element, name: str, route: tuple[tuple[float, float, float, float], ...],
           loop: bool) -> None:
    actor = ET.SubElement(world, "actor", {"name": name})
    skin = ET.SubElement(actor, "skin")
    _text(skin, "filename", ACTOR_SKIN)
    animation = ET.SubElement(actor, "animation", {"name": "walking"})
    _text(animation, "filename", ACTOR_SKIN)
    _text(animation, "interpolate_x", "true")
    script = ET.SubElement(actor, "script")
    _text(script, "loop", "true" if loop else "false")
    _text(script, "delay_start", "0")
    _text(script, "auto_start", "true")
    trajectory = ET.SubElement(script, "trajectory", {"id": "0", "type": "walking"})
    for t, x, y, yaw in route:
        waypoint = ET.SubElement(trajectory, "waypoint")
        _text(waypoint, "time", _num(t))
        _text(waypoint, "pose", _num(x, y, 0.0, 0.0, 0.0, yaw))


def to_sdf(scene: Scene3D) -> str:
    """The SDF world of ``scene``: lights, ground plane, walls, obstacles, terrain and actors.

    Terrain is written as merged boxes (:func:`~arena.sim.mujoco.terrain.terrain_boxes`).
    """
    root = ET.Element("sdf", {"version": SDF_VERSION})
    world = ET.SubElement(root, "world", {"name": sdf_name(scene.name)})
    x0, y0, x1, y1 = scene.bounds
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    for k, direction in enumerate(scene.params.light_directions()):
        light = ET.SubElement(world, "light", {"name": f"light_{k}", "type": "directional"})
        _text(light, "cast_shadows", "false")
        _text(light, "pose", _num(cx, cy, 10.0, 0.0, 0.0, 0.0))
        _text(light, "diffuse", "0.8 0.8 0.8 1")
        _text(light, "direction", _num(*direction))
    if scene.params.floor:
        ground = ET.SubElement(world, "model", {"name": "ground_plane"})
        _text(ground, "static", "true")
        link = ET.SubElement(ground, "link", {"name": "link"})
        for tag in ("collision", "visual"):
            el = ET.SubElement(link, tag, {"name": tag})
            _text(el, "pose", _num(cx, cy, 0.0, 0.0, 0.0, 0.0))
            plane = ET.SubElement(ET.SubElement(el, "geometry"), "plane")
            _text(plane, "normal", "0 0 1")
            _text(plane, "size", _num(x1 - x0, y1 - y0))
    terrain = scene.terrain
    if isinstance(terrain, HeightField):  # SDF height maps need an image file: boxes instead
        terrain = terrain_boxes(terrain.height_map(), max_boxes=scene.params.max_wall_boxes)
    for body in (*scene.static, *(() if terrain is None else (terrain,))):
        _model(world, body, scene)
    for a in scene.actors:
        _actor(world, a.name, a.route, a.loop)
    ET.indent(root)
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
