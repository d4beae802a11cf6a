"""Maps for the scenario editor: packaged worlds, the seven generators, and uploaded maps.

The editor draws a map from :func:`map_json` (the live view's PNG encoding,
:func:`arena.live.frame.grid_png`). Generated maps come from
:data:`~arena.maps.generators.MAP_GENERATORS` with their ``Params`` as a JSON schema (the page
builds its form from it); the obstacles a generator places are burnt into the saved map image,
so that ``arena run --map <root>/_maps/<name>`` (which reads only the map) sees them. Uploaded
maps are a ROS ``map_server`` YAML and its image, read with :func:`arena.maps.io.load_map`
after the size limits below.
"""

from __future__ import annotations

import base64
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml
from PIL import Image

from arena.core.errors import ArenaError, ConfigError
from arena.core.rng import derive_rng
from arena.live.frame import grid_png
from arena.maps.generators import MAP_GENERATORS
from arena.maps.grid import OccupancyGrid
from arena.maps.io import load_map
from arena.maps.raster import burn_obstacles
from arena.maps.sources import WORLDS_DIR, packaged_worlds

MAX_YAML_BYTES = 64 * 1024
"""Largest uploaded ``map.yaml`` (bytes)."""
MAX_IMAGE_BYTES = 8 * 1024 * 1024
"""Largest uploaded map image (bytes)."""
MAX_IMAGE_SIDE = 4000
"""Largest uploaded map image side (pixels)."""


class TooLarge(ArenaError):
    """An upload over the limits (HTTP 413); the message names the file and the limit."""


def map_json(grid: OccupancyGrid) -> dict[str, Any]:
    """The grid as the editor draws it: size (cells), resolution (m), origin (m), base64 PNG."""
    return {"width": grid.width, "height": grid.height, "resolution": grid.resolution,
            "origin": [float(v) for v in grid.origin],
            "png": base64.b64encode(grid_png(grid)).decode("ascii")}


def world_scenarios(world: str) -> list[str]:
    """Names of a packaged world's scenarios (``scenarios/*.json``)."""
    folder = WORLDS_DIR / world / "scenarios"
    return sorted(p.stem for p in folder.glob("*.json")) if folder.is_dir() else []


def world_zones(world: str) -> list[dict[str, Any]]:
    """A packaged world's ``map/zones.yaml`` as read (empty without one)."""
    path = WORLDS_DIR / world / "map" / "zones.yaml"
    if not path.is_file():
        return []
    return list(yaml.safe_load(path.read_text(encoding="utf-8")) or [])


def worlds() -> list[dict[str, Any]]:
    """Every packaged world with its scenario names."""
    return [{"name": w, "scenarios": world_scenarios(w)} for w in packaged_worlds()]


def generators() -> list[dict[str, Any]]:
    """Every map generator: name, one-line summary, tags and its parameters' JSON schema."""
    out = []
    for entry in MAP_GENERATORS.entries():
        model = entry.params_model
        out.append({"name": entry.name, "summary": entry.summary, "tags": list(entry.tags),
                    "schema": model.model_json_schema() if model is not None else {}})
    return out


def generate(name: str, params: dict[str, Any], seed: int) -> OccupancyGrid:
    """Build a map with generator ``name`` (its placed obstacles burnt into the grid).

    Raises:
        UnknownNameError: no such generator (with the closest name).
        ConfigError: bad parameters (naming the key) or a map the generator cannot build.
    """
    source = MAP_GENERATORS.build({"type": name, **params}, source=f"generator {name}")
    result = source.build(derive_rng(seed, "map"))
    return burn_obstacles(result.grid, result.obstacles) if result.obstacles else result.grid


@dataclass(frozen=True)
class Upload:
    """An uploaded map: the YAML's bytes, and the image's file name and bytes."""

    yaml_bytes: bytes
    image_name: str
    image_bytes: bytes


def _limit(data: bytes, limit: int, what: str) -> None:
    if len(data) > limit:
        raise TooLarge(f"{what}: {len(data):,} bytes, the limit is {limit:,} bytes")


def read_upload(upload: Upload) -> OccupancyGrid:
    """The grid of an uploaded map, after the size limits.

    The YAML's ``image`` key must name a plain file (the upload's image is stored under that
    name next to it, in a temporary folder, and read with :func:`~arena.maps.io.load_map`).

    Raises:
        TooLarge: the YAML over :data:`MAX_YAML_BYTES`, the image over :data:`MAX_IMAGE_BYTES`
            or :data:`MAX_IMAGE_SIDE` pixels a side.
        ConfigError: a bad YAML or image, naming ``map.yaml`` and the key.
    """
    _limit(upload.yaml_bytes, MAX_YAML_BYTES, "map.yaml")
    _limit(upload.image_bytes, MAX_IMAGE_BYTES, "map image")
    try:
        doc = yaml.safe_load(upload.yaml_bytes.decode("utf-8"))
    except (UnicodeDecodeError, yaml.YAMLError) as e:
        first = str(e).splitlines()[0] if str(e) else type(e).__name__
        raise ConfigError(f"not a YAML file ({first})", source="map.yaml") from None
    if not isinstance(doc, dict):
        raise ConfigError("expected a mapping of keys (image, resolution, origin, ...)",
                          source="map.yaml")
    image = doc.get("image")
    if not isinstance(image, str) or not image or Path(image).name != image:
        raise ConfigError(f"expected the plain file name of the uploaded image, got {image!r}",
                          source="map.yaml", path="image")
    with tempfile.TemporaryDirectory(prefix="arena-upload-") as tmp:
        (Path(tmp) / "map.yaml").write_bytes(upload.yaml_bytes)
        image_path = Path(tmp) / image
        image_path.write_bytes(upload.image_bytes)
        _check_pixels(image_path, upload.image_name)
        try:
            return load_map(Path(tmp) / "map.yaml")
        except ConfigError as e:
            # The temporary folder means nothing to the user: name the uploaded files.
            message = e.message.replace(str(image_path), upload.image_name or image)
            raise ConfigError(message, source="map.yaml", path=e.path) from None


def _check_pixels(path: Path, name: str) -> None:
    """Refuse an image over :data:`MAX_IMAGE_SIDE` pixels a side (reads the header only)."""
    try:
        with Image.open(path) as im:
            w, h = im.size
    # Pillow raises many types for a bad file; load_map then says what is wrong with it.
    except Exception:
        return
    if max(w, h) > MAX_IMAGE_SIDE:
        raise TooLarge(f"map image {name!r}: {w} × {h} pixels, the limit is {MAX_IMAGE_SIDE} "
                       "pixels a side")
