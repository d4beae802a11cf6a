"""``obstacles.parametrized``: obstacle counts per model from an Arena XML file (specs §2.6).

The file is Arena-Rosnav's ``arena_bringup/configs/parametrized/<file>``::

    <random>
      <static>      <obstacle name="shelf"><min>2</min><max>7</max><model>shelf</model></obstacle>
      </static>
      <interactive> ... </interactive>        (optional)
      <dynamic>     <obstacle name="actor1" min="1" max="3" type="adult" model="actor1"/>
      </dynamic>
    </random>

``min``, ``max``, ``type`` and ``model`` may be sub-elements or attributes (not both with
different values). For every entry the episode draws a count uniformly from ``{min..max}``
(Arena's ``randint(min, max + 1)``). Static and interactive entries name a model of the
obstacle library (``arena/maps/obstacle_models.yaml``, or ``box`` for a random cuboid) and are
placed like ``obstacles.random`` places them; dynamic entries become pedestrians whose ``type``
(``adult``, ``elder``, ``child``, optionally prefixed ``human/``) sets their kind, while their
``model`` (Arena's ``actor1`` ...) is only a label. Pedestrians walk round trips between
mutually visible waypoints, as in ``obstacles.random``.

Difference from Arena: Arena's 2024 loader looks for the interactive and dynamic entries under
``./static/interactive`` and ``./static/dynamic``, so the ``<dynamic>`` block of its own default
file is silently ignored. Here ``./static/obstacle``, ``./interactive/obstacle`` and
``./dynamic/obstacle`` are read, as the file format intends.

Entries are located in errors XPath style, 1-based: ``static/obstacle[2]/model``. Curriculum
count overrides (``staged``) do not apply: the file fixes the counts per model.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pydantic import Field

from arena.core.errors import ConfigError
from arena.maps.obstacles import obstacle_models
from arena.scene.episode import MAX_COUNT, AgentSpawn
from arena.scene.state import Obstacle
from arena.tasks.base import ResetContext, register_mode
from arena.tasks.obstacle_modes.random import (
    BOX,
    PlacementParams,
    place_obstacles,
    place_pedestrians,
)
from arena.tasks.scenario import KIND_CODES

DEFAULT_FILE = Path(__file__).resolve().parent.parent / "data" / "parametrized" / "default.xml"
"""The packaged default: static shelf 2–7; pedestrians actor1 1–3 and actor2 2–4 (adults)."""

SECTIONS = ("static", "interactive", "dynamic")
"""The blocks of the root ``<random>`` element, in placement order."""

FIELDS = ("min", "max", "type", "model")
"""Values of an ``<obstacle>`` entry (sub-elements or attributes)."""

DEFAULT_PED_MODEL = "actor1"
"""Label of a dynamic entry without a model (Arena's default pedestrian model)."""


@dataclass(frozen=True)
class ParametrizedEntry:
    """One ``<obstacle>`` entry of a parametrized file.

    Attributes:
        section: ``static``, ``interactive`` or ``dynamic``.
        name: the entry's ``name`` attribute.
        min, max: count range (inclusive).
        model: library model (static, interactive) or pedestrian model label (dynamic).
        kind: pedestrian type code (0 adult, 1 elder, 2 child); 0 for obstacles.
        where: the entry's XPath-style location (``static/obstacle[2]``) for messages.
    """

    section: str
    name: str
    min: int
    max: int
    model: str
    kind: int
    where: str

    def draw(self, rng: np.random.Generator) -> int:
        """The count for one episode, uniform over ``{min..max}``."""
        return int(rng.integers(self.min, self.max + 1))


def load_parametrized(path: str | Path) -> list[ParametrizedEntry]:
    """Read and check a parametrized XML file.

    Raises:
        ConfigError: naming the file and the entry (``static/obstacle[2]/model``) for a missing
            file, malformed XML (with its line), unknown elements, bad counts, unknown models or
            pedestrian types.
    """
    file = Path(path).expanduser()
    source = str(file)
    if not file.is_file():
        raise ConfigError("parametrized obstacle file not found", source=source)
    try:
        root = ET.parse(file).getroot()
    except ET.ParseError as err:
        line = err.position[0]
        raise ConfigError(f"malformed XML: {err}", source=source, path=f"line {line}") from None
    if root.tag != "random":
        raise ConfigError(
            f"root element must be <random>, got <{root.tag}>", source=source, path=root.tag
        )
    seen: dict[str, int] = {}
    for child in root:
        if child.tag not in SECTIONS:
            raise ConfigError(
                f"unknown block <{child.tag}>; expected: {', '.join(SECTIONS)}",
                source=source,
                path=child.tag,
            )
        seen[child.tag] = seen.get(child.tag, 0) + 1
        if seen[child.tag] > 1:
            raise ConfigError(f"<{child.tag}> appears twice", source=source, path=child.tag)
    entries: list[ParametrizedEntry] = []
    for section in SECTIONS:
        block = root.find(section)
        if block is None:
            continue
        for child in block:
            if child.tag != "obstacle":
                raise ConfigError(
                    f"unknown element <{child.tag}>; a block holds <obstacle> entries",
                    source=source,
                    path=f"{section}/{child.tag}",
                )
        for k, el in enumerate(block.findall("obstacle"), start=1):
            entries.append(_entry(el, section, f"{section}/obstacle[{k}]", source))
    return entries


def _entry(el: ET.Element, section: str, where: str, source: str) -> ParametrizedEntry:
    def fail(message: str, key: str | None = None) -> ConfigError:
        return ConfigError(message, source=source, path=f"{where}/{key}" if key else where)

    for attr in el.attrib:
        if attr not in ("name", *FIELDS):
            raise fail(f"unknown attribute {attr!r}; known: name, {', '.join(FIELDS)}", attr)
    values: dict[str, str] = {}
    for child in el:
        if child.tag not in FIELDS:
            raise fail(f"unknown element <{child.tag}>; known: {', '.join(FIELDS)}", child.tag)
        if child.tag in values:
            raise fail(f"<{child.tag}> given twice", child.tag)
        values[child.tag] = (child.text or "").strip()
    for key, text in el.attrib.items():
        if key in FIELDS:
            if key in values and values[key] != text.strip():
                raise fail(
                    f"given as attribute ({text!r}) and element ({values[key]!r}) with different "
                    "values",
                    key,
                )
            values[key] = text.strip()

    def count(key: str, default: int | None) -> int:
        if key not in values:
            if default is None:
                raise fail(f"missing <{key}> (count, an integer >= 0)", key)
            return default
        try:
            n = int(values[key])
        except ValueError:
            raise fail(f"expected an integer >= 0, got {values[key]!r}", key) from None
        if not 0 <= n <= MAX_COUNT:
            raise fail(f"expected an integer in [0, {MAX_COUNT:,}], got {n}", key)
        return n

    lo = count("min", None)
    hi = count("max", lo)
    if lo > hi:
        raise fail(f"min ({lo}) must not exceed max ({hi})", "max")
    name = el.attrib.get("name", "").strip()
    kind = 0
    if section == "dynamic":
        model = values.get("model") or DEFAULT_PED_MODEL
        ped_type = values.get("type", "adult").removeprefix("human/")
        if ped_type not in KIND_CODES:
            raise fail(
                f"unknown pedestrian type {values['type']!r}; known: {', '.join(KIND_CODES)}",
                "type",
            )
        kind = KIND_CODES[ped_type]
    else:
        if not values.get("model"):
            raise fail("missing <model> (an obstacle library model)", "model")
        model = values["model"].removesuffix(".yaml")
        if model != BOX and model not in obstacle_models():
            known = ", ".join([BOX, *sorted(obstacle_models())])
            raise fail(f"unknown obstacle model {values['model']!r}; known: {known}", "model")
    return ParametrizedEntry(section, name or model, lo, hi, model, kind, where)


@register_mode("obstacles", "parametrized")
class ParametrizedObstacles:
    """Obstacles and pedestrians per model, counts drawn from an Arena parametrized XML file."""

    class Params(PlacementParams):
        """Parameters of ``obstacles.parametrized``."""

        file: str | None = Field(
            None, description="parametrized XML file; default: the packaged default.xml"
        )

    def __init__(self, params: Params | None = None) -> None:
        self.params = params or self.Params()
        self.file = Path(self.params.file).expanduser() if self.params.file else DEFAULT_FILE
        self.entries = load_parametrized(self.file)

    def reset(self, ctx: ResetContext) -> tuple[list[Obstacle], AgentSpawn]:
        """Counts per entry (stream ``obstacles``), obstacles, then pedestrians."""
        p = self.params
        rng = ctx.rng("obstacles")
        counts = [e.draw(rng) for e in self.entries]
        placed: list[Obstacle] = []
        kinds: list[int] = []
        names: dict[str, int] = {}
        for entry, n in zip(self.entries, counts, strict=True):
            if entry.section == "dynamic":
                kinds += [entry.kind] * n
            else:
                prefix = "S" if entry.section == "static" else "I"
                placed += place_obstacles(
                    ctx, prefix, n, [entry.model], rng, p, counter=names,
                    field=f"{self.file}: {entry.where}",
                )
        agents = place_pedestrians(
            ctx,
            len(kinds),
            placed,
            ctx.rng("pedestrians"),
            p,
            kinds=np.array(kinds, dtype=np.int64),
        )
        return placed, agents
