"""Read and write maps in the ROS ``map_server`` format: a ``map.yaml`` next to a PGM/PNG image.

Loading follows ROS 1 ``map_server`` (``src/image_loader.cpp``, noetic) pixel for pixel:

* The colour channels of a pixel are averaged (``avg``, 0..255). In ``trinary`` mode an alpha
  channel is averaged in as if it were a colour (ROS keeps that "to preserve existing behaviour");
  in ``scale`` and ``raw`` mode it is left out.
* ``negate: 1`` replaces ``avg`` by ``255 − avg``. Then ``p = (255 − avg) / 255`` is the occupancy
  probability: ``p > occupied_thresh`` → occupied, ``p < free_thresh`` → free, else unknown.
* Image row 0 is the top of the picture (highest y); :class:`OccupancyGrid` row 0 is the bottom,
  so rows are flipped.

Arena grids are trinary by design (0 / 100 / −1), so the two non-trinary ROS modes are collapsed
after computing the exact ROS cell value ``v`` (see :data:`SCALED_OCCUPIED`):

* ``scale``: ``v`` is 100 above ``occupied_thresh``, 0 below ``free_thresh``, and in between
  ``⌊99·(p − free_thresh)/(occupied_thresh − free_thresh)⌋``, or −1 where the pixel is fully
  transparent. Then ``v ≥ 65`` → occupied, ``0 ≤ v < 65`` → free, −1 → unknown.
* ``raw``: ``v = ⌊avg⌋`` (after negation). ``v ≥ 65`` → occupied, ``v < 65`` → free, and
  ``v > 100`` (e.g. 255) → unknown, since ROS would store those as meaningless negative int8.

Image decoding follows SDL_image as ROS uses it: 16-bit images keep their high byte (libpng
``strip_16``); grey+alpha becomes RGBA (grey counts three times in the trinary mean); a palette
PNG with translucent entries becomes RGBA (Arena's ``map_empty/map.png`` is one: its two
transparent black entries load as occupied, its 50 % and 75 % grey as unknown). It differs only
where SDL's behaviour is an accident: other palette images are read by their colours (SDL would
hand over the palette indices, which only agree for a grey-ramp palette), and in ``scale`` mode an
RGB image without alpha is treated as opaque (ROS reads its blue channel as alpha).

Saving writes what ``map_saver`` writes: a trinary image (occupied 0, free 254, unknown 205) and a
YAML with exactly ``image, resolution, origin, negate, occupied_thresh, free_thresh``.
"""

from __future__ import annotations

import difflib
import json
import math
import os
import re
from pathlib import Path
from typing import Any, Literal

import numpy as np
import yaml
from numpy.typing import NDArray
from PIL import Image
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    FiniteFloat,
    ValidationError,
    ValidationInfo,
    field_validator,
)

from arena.core import files
from arena.core.errors import ConfigError, format_loc
from arena.maps.grid import FREE, MAX_CELLS, MAX_COORDINATE, OCCUPIED, UNKNOWN, OccupancyGrid

__all__ = [
    "SCALED_OCCUPIED",
    "MapMetadata",
    "load_map",
    "load_map_with_metadata",
    "pixels_to_cells",
    "save_map",
]

SCALED_OCCUPIED = 65
"""ROS cell value (0..100) from which a ``scale``/``raw`` map cell counts as occupied.

ROS cell values are occupancy percentages; 65 mirrors the default ``occupied_thresh`` of 0.65,
so a cell whose value reaches 65 % is a wall and anything lower is free.
"""

# Pixel values map_saver writes (occupied, free, unknown); with the default thresholds they load
# back as the same classes: p(0) = 1 > 0.65, p(254) = 0.004 < 0.196, p(205) = 0.19608 in between.
_SAVE_OCCUPIED = 0
_SAVE_FREE = 254
_SAVE_UNKNOWN = 205

_YAW_TOLERANCE = 1e-9  # rad; absorbs quaternion round-off in yaws written as "0.000000"


class MapMetadata(BaseModel):
    """The contents of a ROS ``map_server`` ``map.yaml``.

    Attributes:
        image: image file, relative to the YAML's folder or absolute.
        resolution: cell edge length (m/cell), > 0.
        origin: ``(x, y, yaw)`` of the lower-left corner of the lower-left pixel (m, m, rad).
            Only yaw 0 is supported.
        negate: whether white means occupied instead of free (YAML ``0``/``1`` or a bool).
        occupied_thresh: occupancy probability above which a cell is occupied, in [0, 1].
        free_thresh: occupancy probability below which a cell is free, in [0, 1], below
            ``occupied_thresh``.
        mode: ROS interpretation: ``trinary`` (default), ``scale`` or ``raw`` (module docstring).
        type: Arena's own tag (e.g. ``indoor``); kept, not used.
    """

    model_config = ConfigDict(frozen=True, extra="forbid")

    image: str = Field(min_length=1)
    resolution: float = Field(gt=0, allow_inf_nan=False)
    origin: tuple[FiniteFloat, FiniteFloat, FiniteFloat]
    negate: bool = False
    occupied_thresh: float = Field(0.65, ge=0.0, le=1.0)
    free_thresh: float = Field(0.196, ge=0.0, le=1.0)
    mode: Literal["trinary", "scale", "raw"] = "trinary"
    type: str | None = None

    @field_validator("negate", mode="before")
    @classmethod
    def _negate_flag(cls, v: Any) -> Any:
        # ROS reads negate as an int; pydantic alone would also take "yes", 0.0 or "1".
        if isinstance(v, bool) or (isinstance(v, int) and v in (0, 1)):
            return bool(v)
        raise ValueError(f"negate must be 0, 1, true or false, got {v!r}")

    @field_validator("origin")
    @classmethod
    def _no_rotation(cls, v: tuple[float, float, float]) -> tuple[float, float, float]:
        if abs(v[2]) > _YAW_TOLERANCE:
            raise ValueError(
                f"rotated maps are not supported: the origin yaw must be 0 rad, got {v[2]!r} "
                "(ROS map_server mostly ignores it as well); rotate the image instead"
            )
        if max(abs(v[0]), abs(v[1])) > MAX_COORDINATE:
            raise ValueError(
                f"origin x and y must lie within ±{MAX_COORDINATE:g} m, got {v[:2]!r} (float64 "
                "positions that far out cannot resolve map cells)"
            )
        return (v[0], v[1], 0.0)

    @field_validator("free_thresh")
    @classmethod
    def _below_occupied(cls, v: float, info: ValidationInfo) -> float:
        occ = info.data.get("occupied_thresh")
        if occ is not None and not v < occ:
            raise ValueError(f"free_thresh ({v}) must be below occupied_thresh ({occ})")
        return v

    def image_path(self, yaml_dir: str | os.PathLike[str]) -> Path:
        """Where the image lies: :attr:`image` itself if absolute, else inside ``yaml_dir``."""
        p = Path(self.image)
        return p if p.is_absolute() else Path(yaml_dir) / p


# -- loading ------------------------------------------------------------------------------------
def load_map(path: str | os.PathLike[str], *, unknown_is_occupied: bool = False) -> OccupancyGrid:
    """Load a ROS ``map.yaml`` and its image as an :class:`OccupancyGrid`.

    Args:
        path: the ``map.yaml`` file.
        unknown_is_occupied: passed on to the grid (whether unknown cells block).

    Returns:
        The grid, ``(height, width)`` = the image's pixel size, row 0 at the lowest y.

    Raises:
        ConfigError: naming the YAML file and the key when the YAML or the image is unusable.
    """
    return load_map_with_metadata(path, unknown_is_occupied=unknown_is_occupied)[0]


def load_map_with_metadata(
    path: str | os.PathLike[str], *, unknown_is_occupied: bool = False
) -> tuple[OccupancyGrid, MapMetadata]:
    """Like :func:`load_map`, also returning the parsed :class:`MapMetadata`."""
    yaml_path = Path(path)
    source = str(yaml_path)
    meta = _parse_metadata(_read_yaml(yaml_path), source)
    channels, has_alpha = _read_image(meta.image_path(yaml_path.parent), source)
    cells = pixels_to_cells(channels, meta, has_alpha=has_alpha)
    grid = OccupancyGrid(
        np.flipud(cells), meta.resolution, (meta.origin[0], meta.origin[1]), unknown_is_occupied
    )
    return grid, meta


def _read_yaml(yaml_path: Path) -> dict[str, Any]:
    source = str(yaml_path)
    doc = files.read_yaml(yaml_path, what="map file")
    if doc is None:
        raise ConfigError(
            "the map file is empty; expected keys image, resolution, origin, ...", source=source
        )
    if not isinstance(doc, dict):
        raise ConfigError(
            f"expected a mapping of keys (image, resolution, origin, ...), "
            f"got a {type(doc).__name__}",
            source=source,
        )
    return doc


def _parse_metadata(doc: dict[Any, Any], source: str) -> MapMetadata:
    known = list(MapMetadata.model_fields)
    for key in doc:
        if key not in known:
            close = difflib.get_close_matches(str(key), known, n=1, cutoff=0.6)
            hint = f"did you mean {close[0]!r}? " if close else ""
            raise ConfigError(
                f"unknown key; {hint}map.yaml keys are: {', '.join(known)}",
                source=source,
                path=str(key),
            )
    try:
        return MapMetadata.model_validate(doc)
    except ValidationError as e:
        raise _metadata_error(e, source) from None


def _metadata_error(err: ValidationError, source: str) -> ConfigError:
    """Merge pydantic errors into one ConfigError: the first names the key, the others follow."""
    parts: list[tuple[str, str]] = []
    for e in err.errors(include_url=False):
        loc = format_loc(e["loc"][:1])  # "origin", not "origin[2]": the key is what users edit
        if e["type"] == "missing":
            text = "required key is missing"
        elif e["type"] == "value_error":
            text = str(e["ctx"]["error"])
        else:
            text = f"{e['msg']} (got {e.get('input')!r})"
        parts.append((loc, text))
    head_loc, head = parts[0]
    rest = "".join(f"; {loc}: {text}" for loc, text in parts[1:])
    return ConfigError(head + rest, source=source, path=head_loc or None)


def _read_image(image_path: Path, source: str) -> tuple[NDArray[np.uint8], bool]:
    """Decode the image to ``(H, W, C)`` uint8 channels; ``True`` if the last one is alpha."""
    if not image_path.is_file():
        raise ConfigError(
            f"image file not found (looked for {image_path})", source=source, path="image"
        )
    try:
        with Image.open(image_path) as im:
            if im.size[0] * im.size[1] > MAX_CELLS:
                raise ValueError(f"{im.size[0]} × {im.size[1]} pixels; a map has at most "
                                 f"{MAX_CELLS:,} cells")
            im.load()
            return _channels(im)
    # Pillow raises OSError, ValueError, SyntaxError, struct.error, DecompressionBombError ...
    # for bad files; any of them means the same thing to the user.
    except Exception as e:
        raise ConfigError(
            f"cannot read image {image_path}: {e}", source=source, path="image"
        ) from None


def _channels(im: Image.Image) -> tuple[NDArray[np.uint8], bool]:
    mode = im.mode
    if mode.startswith("I;16") or mode == "I":
        # 16-bit grey (PNG, or PGM with maxval > 255): keep the high byte like libpng strip_16.
        a = np.clip(np.asarray(im).astype(np.int64), 0, 65535) >> 8
        return a.astype(np.uint8)[..., None], False
    if mode == "1":
        im = im.convert("L")
    elif mode == "P":
        im = im.convert("RGBA" if "transparency" in im.info else "RGB")
    elif mode in ("LA", "La", "PA", "RGBa"):
        im = im.convert("RGBA")
    elif mode in ("RGBX", "CMYK", "YCbCr", "LAB", "HSV"):
        im = im.convert("RGB")
    elif mode not in ("L", "RGB", "RGBA"):
        raise ValueError(f"unsupported image mode {mode!r} (use 8/16-bit grey, RGB or RGBA)")
    a = np.asarray(im, dtype=np.uint8)
    if a.ndim == 2:
        a = a[..., None]
    return a, im.mode == "RGBA"


def pixels_to_cells(
    channels: NDArray[np.uint8], meta: MapMetadata, *, has_alpha: bool = False
) -> NDArray[np.int8]:
    """Classify image pixels as ROS ``map_server`` does, collapsed to Arena's trinary values.

    Args:
        channels: ``(H, W, C)`` (or ``(H, W)`` grey) uint8 pixels, image row 0 at the top.
        meta: supplies ``negate``, the thresholds and ``mode``.
        has_alpha: whether the last channel is alpha (C ≥ 2).

    Returns:
        ``(H, W)`` int8 cells 0 / 100 / −1 in image row order (not yet flipped).
    """
    c = np.asarray(channels)
    if c.ndim == 2:
        c = c[..., None]
    c = c.astype(np.float64)
    n = c.shape[-1]
    # Trinary mode averages alpha in with the colours (as ROS does); the others leave it out.
    use = n - 1 if (has_alpha and meta.mode != "trinary") else n
    avg = c[..., :use].sum(axis=-1) / use
    if meta.negate:
        avg = 255.0 - avg

    if meta.mode == "raw":
        v = np.floor(avg)  # ROS: unsigned char value = color_avg
        value = np.where(v > 100, UNKNOWN, v)
        return _collapse(value)

    occ = (255.0 - avg) / 255.0
    is_occ = occ > meta.occupied_thresh
    is_free = occ < meta.free_thresh
    if meta.mode == "trinary":
        return np.where(is_occ, OCCUPIED, np.where(is_free, FREE, UNKNOWN)).astype(np.int8)

    # scale: in-between pixels get 0..99, or unknown where fully transparent (alpha < 1).
    ratio = (occ - meta.free_thresh) / (meta.occupied_thresh - meta.free_thresh)
    between = np.floor(99.0 * ratio)
    if has_alpha:
        between = np.where(c[..., -1] < 1.0, UNKNOWN, between)
    value = np.where(is_occ, OCCUPIED, np.where(is_free, FREE, between))
    return _collapse(value)


def _collapse(value: NDArray[np.float64]) -> NDArray[np.int8]:
    """ROS cell values −1 or 0..100 → trinary, occupied from :data:`SCALED_OCCUPIED`."""
    out = np.where(value >= SCALED_OCCUPIED, OCCUPIED, FREE)
    return np.where(value < 0, UNKNOWN, out).astype(np.int8)


# -- saving -------------------------------------------------------------------------------------
_FORMATS = {"pgm": "PPM", "png": "PNG"}  # Pillow writes binary P5 for an "L" image via PPM


def save_map(
    grid: OccupancyGrid,
    yaml_path: str | os.PathLike[str],
    *,
    image_format: Literal["pgm", "png"] = "pgm",
    image_name: str | None = None,
) -> Path:
    """Write ``grid`` as a ``map_saver``-style map: a trinary image plus its ``map.yaml``.

    Args:
        grid: the map. Its ``unknown_is_occupied`` flag is not stored (ROS has no such key).
        yaml_path: the YAML file to write; the image goes into the same folder (created if
            missing). Existing files are overwritten.
        image_format: ``"pgm"`` (binary P5, as map_saver) or ``"png"``.
        image_name: image file name; default: the YAML's stem plus ``.pgm``/``.png``.

    Returns:
        The path of the YAML written.

    Raises:
        ValueError: unknown ``image_format``, or an ``image_name`` that is a path or whose
            suffix contradicts ``image_format``.
    """
    if image_format not in _FORMATS:
        raise ValueError(f"image_format must be 'pgm' or 'png', got {image_format!r}")
    yaml_path = Path(yaml_path)
    name = image_name or f"{yaml_path.stem}.{image_format}"
    if Path(name).name != name:
        raise ValueError(f"image_name must be a plain file name, got {name!r}")
    if Path(name).suffix.lower() != f".{image_format}":
        raise ValueError(f"image_name {name!r} does not end in .{image_format}")

    pixels = np.full(grid.data.shape, _SAVE_UNKNOWN, dtype=np.uint8)
    pixels[grid.data == FREE] = _SAVE_FREE
    pixels[grid.data == OCCUPIED] = _SAVE_OCCUPIED
    files.make_dir(yaml_path.parent, what="map folder")
    Image.fromarray(np.flipud(pixels), mode="L").save(
        yaml_path.parent / name, format=_FORMATS[image_format]
    )

    ox, oy = grid.origin
    yaml_path.write_text(
        f"image: {_yaml_str(name)}\n"
        f"resolution: {_yaml_float(grid.resolution)}\n"
        f"origin: [{_yaml_float(ox)}, {_yaml_float(oy)}, 0.0]\n"
        "negate: 0\n"
        "occupied_thresh: 0.65\n"
        "free_thresh: 0.196\n"
    )
    return yaml_path


def _yaml_str(s: str) -> str:
    """``s`` plain when YAML reads it back as the same string, else double-quoted."""
    if re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9_.\-]*", s) and yaml.safe_load(s) == s:
        return s
    return json.dumps(s)  # a JSON string is a valid YAML double-quoted scalar


def _yaml_float(x: float) -> str:
    """Shortest exact decimal without exponent (PyYAML reads ``1e-05`` as a string)."""
    if not math.isfinite(x):
        raise ValueError(f"cannot save a non-finite map coordinate {x!r}")
    return np.format_float_positional(x, unique=True, trim="0")
