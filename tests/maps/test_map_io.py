"""ROS map_server file I/O: map.yaml parsing, pixel interpretation, map_saver output, errors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from PIL import Image

from arena.core.errors import ConfigError
from arena.maps import (
    FREE,
    OCCUPIED,
    UNKNOWN,
    MapMetadata,
    OccupancyGrid,
    load_map,
    load_map_with_metadata,
    save_map,
)
from arena.maps.io import pixels_to_cells

ROS_YAML = """\
image: map.pgm
resolution: 0.100000
origin: [-20.000000, -20.000000, 0.000000]
negate: 0
occupied_thresh: 0.65
free_thresh: 0.196

"""

# map_empty's map.yaml from Arena, verbatim in layout: sorted keys, block-list origin, `type`.
BLOCK_STYLE_YAML = """\
free_thresh: 0.196
image: map.png
negate: 0
occupied_thresh: 0.65
origin:
  - 0.0
  - 0.0
  - 0.0
resolution: 0.05
type: indoor
"""

X, F, U = OCCUPIED, FREE, UNKNOWN  # wall, free, unknown: short names for expected rows


def _write_map(
    folder: Path, pixels, *, pil_mode: str | None = None, image: str = "map.png", **keys
) -> Path:
    """Write ``pixels`` (image rows, top first) and a map.yaml with ``keys`` over defaults."""
    arr = np.asarray(pixels, dtype=np.uint8)
    Image.fromarray(arr, mode=pil_mode).save(folder / image)
    doc = {"image": image, "resolution": 0.1, "origin": [-20.0, -20.0, 0.0], "negate": 0,
           "occupied_thresh": 0.65, "free_thresh": 0.196}
    doc.update(keys)
    path = folder / "map.yaml"
    path.write_text(yaml.safe_dump(doc))
    return path


def _meta(**kw) -> MapMetadata:
    return MapMetadata(image="m.png", resolution=0.1, origin=(0.0, 0.0, 0.0), **kw)


def _pattern() -> OccupancyGrid:
    """30 × 40 map with all three values and no symmetry, row 0 at the lowest y."""
    data = np.zeros((30, 40), dtype=np.int8)
    data[0, :] = OCCUPIED  # bottom wall only
    data[:, 0] = OCCUPIED  # left wall only
    data[5:9, 20:33] = OCCUPIED
    data[20:29, 3:6] = UNKNOWN
    data[25, 30] = OCCUPIED
    return OccupancyGrid(data, 0.1, (-20.0, -20.0))


# -- round trips ----------------------------------------------------------------------------------
@pytest.mark.parametrize("fmt", ["pgm", "png"])
def test_round_trip(tmp_path, fmt):
    grid = _pattern()
    out = save_map(grid, tmp_path / "map.yaml", image_format=fmt)
    assert out == tmp_path / "map.yaml"
    assert (tmp_path / f"map.{fmt}").is_file()
    back, meta = load_map_with_metadata(out)
    assert back == grid
    assert meta.image == f"map.{fmt}"
    assert meta.resolution == 0.1
    assert meta.origin == (-20.0, -20.0, 0.0)


def test_round_trip_catches_missing_flip(tmp_path):
    grid = _pattern()
    save_map(grid, tmp_path / "map.yaml")
    back = load_map(tmp_path / "map.yaml")
    assert not np.array_equal(np.flipud(back.data), grid.data)
    assert not np.array_equal(np.fliplr(back.data), grid.data)


def test_saved_files_are_map_saver_style(tmp_path):
    grid = OccupancyGrid(np.array([[0, 100, -1], [0, 0, 0]], dtype=np.int8), 0.05, (-3.5, 1.0))
    save_map(grid, tmp_path / "m.yaml")
    raw = (tmp_path / "m.pgm").read_bytes()
    assert raw.startswith(b"P5")
    img = np.asarray(Image.open(tmp_path / "m.pgm"))
    # Image row 0 is the top = grid row 1; grid row 0 (the origin row) is the bottom row.
    np.testing.assert_array_equal(img, [[254, 254, 254], [254, 0, 205]])
    doc = yaml.safe_load((tmp_path / "m.yaml").read_text())
    assert list(doc) == [
        "image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh"
    ]
    assert doc == {"image": "m.pgm", "resolution": 0.05, "origin": [-3.5, 1.0, 0.0],
                   "negate": 0, "occupied_thresh": 0.65, "free_thresh": 0.196}


def test_round_trip_awkward_floats_and_names(tmp_path):
    grid = OccupancyGrid(np.array([[0, 100]], dtype=np.int8), 0.00001, (-1.23456789012345, 7e-7))
    out = save_map(grid, tmp_path / "sub" / "my map.yaml", image_format="png",
                   image_name="my map: v2.png")
    assert load_map(out) == grid
    assert (tmp_path / "sub" / "my map: v2.png").is_file()


def test_save_rejects_bad_arguments(tmp_path):
    g = _pattern()
    with pytest.raises(ValueError, match="image_format"):
        save_map(g, tmp_path / "a.yaml", image_format="jpg")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"\.pgm"):
        save_map(g, tmp_path / "a.yaml", image_name="a.png")
    with pytest.raises(ValueError, match="plain file name"):
        save_map(g, tmp_path / "a.yaml", image_name="x/a.pgm")


def test_unknown_is_occupied_passed_on(tmp_path):
    save_map(_pattern(), tmp_path / "map.yaml")
    g = load_map(tmp_path / "map.yaml", unknown_is_occupied=True)
    assert g.unknown_is_occupied
    assert g.occupied[20, 3]


# -- orientation ----------------------------------------------------------------------------------
def test_top_left_pixel_lands_at_top_left_of_world(tmp_path):
    h, w, res, ox, oy = 4, 5, 0.1, -20.0, -20.0
    pixels = np.full((h, w), 254, dtype=np.uint8)
    pixels[0, 0] = 0  # image top-left
    path = _write_map(tmp_path, pixels, image="map.pgm")
    g = load_map(path)
    assert (g.height, g.width) == (h, w)
    assert g.data[h - 1, 0] == OCCUPIED
    assert int(g.occupied.sum()) == 1
    assert g.is_occupied([ox + res / 2, oy + (h - 0.5) * res])
    assert not g.is_occupied([ox + res / 2, oy + res / 2])
    assert not g.is_occupied([ox + (w - 0.5) * res, oy + (h - 0.5) * res])


def test_real_ros_yaml_layout(tmp_path):
    Image.fromarray(np.array([[0, 254], [205, 254]], dtype=np.uint8)).save(tmp_path / "map.pgm")
    (tmp_path / "map.yaml").write_text(ROS_YAML)
    g, meta = load_map_with_metadata(tmp_path / "map.yaml")
    np.testing.assert_array_equal(g.data, [[U, F], [X, F]])
    assert g.origin == (-20.0, -20.0)
    assert g.resolution == 0.1
    assert meta.negate is False
    assert meta.mode == "trinary"
    assert meta.type is None


def test_block_list_yaml_with_type(tmp_path):
    Image.fromarray(np.array([[255, 0, 0]], dtype=np.uint8)).save(tmp_path / "map.png")
    (tmp_path / "map.yaml").write_text(BLOCK_STYLE_YAML)
    g, meta = load_map_with_metadata(str(tmp_path / "map.yaml"))
    assert meta.type == "indoor"
    assert meta.origin == (0.0, 0.0, 0.0)
    assert g.origin == (0.0, 0.0)
    assert g.resolution == 0.05
    np.testing.assert_array_equal(g.data, [[F, X, X]])


def test_absolute_image_path(tmp_path):
    (tmp_path / "img").mkdir()
    Image.fromarray(np.array([[0]], dtype=np.uint8)).save(tmp_path / "img" / "a.pgm")
    doc = {"image": str(tmp_path / "img" / "a.pgm"), "resolution": 0.5, "origin": [1, 2, 0]}
    (tmp_path / "m.yaml").write_text(yaml.safe_dump(doc))
    g, meta = load_map_with_metadata(tmp_path / "m.yaml")
    assert g.data[0, 0] == OCCUPIED
    assert g.origin == (1.0, 2.0)
    assert meta.occupied_thresh == 0.65
    assert meta.free_thresh == 0.196


# -- trinary thresholds ---------------------------------------------------------------------------
# p = (255 − v)/255: v=0 → 1.0, 100 → 0.608, 205 → 0.19608, 254 → 0.0039, 255 → 0.
GREYS = [0, 100, 205, 254, 255]


@pytest.mark.parametrize(
    ("keys", "expected"),
    [
        ({}, [X, U, U, F, F]),
        # negate: p = v/255: 0 → 0, 100 → 0.392, 205 → 0.804, 254/255 → ~1.
        ({"negate": 1}, [F, U, X, X, X]),
        ({"negate": True}, [F, U, X, X, X]),
        ({"occupied_thresh": 0.5}, [X, X, U, F, F]),  # 0.608 > 0.5
        ({"free_thresh": 0.25}, [X, U, F, F, F]),  # 0.19608 < 0.25
        ({"free_thresh": 0.0, "occupied_thresh": 1.0}, [U, U, U, U, U]),  # strict comparisons
    ],
)
def test_trinary_rules(tmp_path, keys, expected):
    path = _write_map(tmp_path, [GREYS], image="map.pgm", **keys)
    np.testing.assert_array_equal(load_map(path).data, [expected])


def test_thresholds_are_strict():
    row = np.array([[100]], dtype=np.uint8)  # p = 155/255 exactly
    at = _meta(occupied_thresh=155 / 255)
    assert pixels_to_cells(row, at)[0, 0] == UNKNOWN
    assert pixels_to_cells(row, _meta(free_thresh=155 / 255, occupied_thresh=0.9))[0, 0] == UNKNOWN


def test_ascii_pgm(tmp_path):
    (tmp_path / "map.pgm").write_bytes(b"P2\n# hand written\n3 1\n255\n0 205 254\n")
    (tmp_path / "map.yaml").write_text(ROS_YAML)
    np.testing.assert_array_equal(load_map(tmp_path / "map.yaml").data, [[X, U, F]])


def test_16_bit_png_keeps_high_byte(tmp_path):
    # High bytes 0, 128, 255, 205, 206; 0xCE00 / 257 would round to 205 (unknown) instead.
    px = np.array([[0, 0x8000, 0xFFFF, 0xCD00, 0xCE00]], dtype=np.uint16)
    path = _write_map(tmp_path, np.zeros((1, 5)), image="map.png")
    Image.fromarray(px).save(tmp_path / "map.png")
    assert Image.open(tmp_path / "map.png").mode.startswith("I")
    np.testing.assert_array_equal(load_map(path).data, [[X, U, F, U, F]])


def test_rgb(tmp_path):
    # Means: 85 → p 0.667 (occupied), 170 → 0.333 (unknown), 250 → 0.0196 (free).
    px = np.array([[[255, 0, 0], [0, 255, 255], [255, 255, 240]]], dtype=np.uint8)
    path = _write_map(tmp_path, px, pil_mode="RGB")
    np.testing.assert_array_equal(load_map(path).data, [[X, U, F]])


def test_rgba_trinary_averages_alpha_in(tmp_path):
    # ROS averages alpha with the colours in trinary mode:
    # (255,255,255,255) → 255 free; (255,255,255,0) → 191.25, p 0.25 unknown;
    # (0,0,0,255) → 63.75, p 0.75 occupied; (0,0,0,0) → 0 occupied.
    px = np.array(
        [[[255, 255, 255, 255], [255, 255, 255, 0], [0, 0, 0, 255], [0, 0, 0, 0]]],
        dtype=np.uint8,
    )
    path = _write_map(tmp_path, px, pil_mode="RGBA")
    np.testing.assert_array_equal(load_map(path).data, [[F, U, X, X]])


def test_grey_alpha_counts_as_rgba(tmp_path):
    px = np.array([[[255, 255], [255, 0]]], dtype=np.uint8)  # mean (3·255 + 0)/4 = 191.25
    path = _write_map(tmp_path, px, pil_mode="LA")
    np.testing.assert_array_equal(load_map(path).data, [[F, U]])


def test_palette_with_translucent_entries(tmp_path):
    # Like Arena's map_empty/map.png (there index 0 is transparent black, 1 half-transparent
    # black); here index 0 is transparent white, so dropping alpha would make it free.
    img = Image.new("P", (4, 1))
    img.putpalette([255, 255, 255, 0, 0, 0, 255, 255, 255, 127, 127, 127])
    img.putdata([0, 1, 2, 3])
    img.info["transparency"] = bytes([0, 128])
    img.save(tmp_path / "map.png", transparency=bytes([0, 128]))
    doc = {"image": "map.png", "resolution": 0.05, "origin": [0, 0, 0]}
    (tmp_path / "map.yaml").write_text(yaml.safe_dump(doc))
    # Means with alpha: 191.25 (p 0.25), 32, 255, 159 (p 0.376) → U, X, F, U.
    np.testing.assert_array_equal(load_map(tmp_path / "map.yaml").data, [[U, X, F, U]])


# -- scale and raw modes --------------------------------------------------------------------------
def test_scale_mode_collapses_at_65():
    # In-between p → ⌊99·(p − 0.196)/(0.65 − 0.196)⌋: v=100 → 89, 120 → 72, 140 → 55, 180 → 21.
    px = np.array([[0, 100, 120, 140, 180, 205, 254]], dtype=np.uint8)
    np.testing.assert_array_equal(
        pixels_to_cells(px, _meta(mode="scale")), [[X, X, X, F, F, F, F]]
    )
    # Trinary would call the middle five unknown.
    np.testing.assert_array_equal(pixels_to_cells(px, _meta()), [[X, U, U, U, U, U, F]])


def test_scale_mode_alpha(tmp_path):
    # Scale mode leaves alpha out of the mean; fully transparent in-between pixels are unknown.
    px = np.array(
        [[[180, 180, 180, 0], [180, 180, 180, 255], [0, 0, 0, 0], [255, 255, 255, 0]]],
        dtype=np.uint8,
    )
    path = _write_map(tmp_path, px, pil_mode="RGBA", mode="scale")
    np.testing.assert_array_equal(load_map(path).data, [[U, F, X, F]])


def test_raw_mode():
    px = np.array([[0, 64, 65, 100, 101, 255]], dtype=np.uint8)
    np.testing.assert_array_equal(pixels_to_cells(px, _meta(mode="raw")), [[F, F, X, X, U, U]])
    neg = 255 - px  # negate: value = 255 − pixel
    np.testing.assert_array_equal(
        pixels_to_cells(neg, _meta(mode="raw", negate=True)), [[F, F, X, X, U, U]]
    )


# -- metadata model -------------------------------------------------------------------------------
def test_metadata_defaults_and_frozen():
    m = _meta()
    assert (m.negate, m.occupied_thresh, m.free_thresh, m.mode, m.type) == (
        False, 0.65, 0.196, "trinary", None
    )
    with pytest.raises(Exception, match="frozen"):
        m.resolution = 1.0  # type: ignore[misc]
    assert m.image_path("/x/y") == Path("/x/y/m.png")


# -- errors ---------------------------------------------------------------------------------------
def _error(path: Path) -> str:
    with pytest.raises(ConfigError) as info:
        load_map(path)
    return str(info.value)


def _yaml(tmp_path: Path, text: str, name: str = "bad_map.yaml") -> Path:
    Image.fromarray(np.zeros((2, 2), dtype=np.uint8)).save(tmp_path / "map.pgm")
    p = tmp_path / name
    p.write_text(text)
    return p


def test_missing_yaml(tmp_path):
    msg = _error(tmp_path / "nope.yaml")
    assert "nope.yaml" in msg
    assert "not found" in msg


def test_yaml_is_a_folder(tmp_path):
    (tmp_path / "dir.yaml").mkdir()
    assert "dir.yaml" in _error(tmp_path / "dir.yaml")


def test_malformed_yaml_names_line(tmp_path):
    p = _yaml(tmp_path, "image: map.pgm\nresolution: 0.1\n  origin: [0, 0, 0]\n")
    msg = _error(p)
    assert "bad_map.yaml" in msg
    assert "line 3" in msg
    assert "malformed YAML" in msg


def test_yaml_not_a_mapping(tmp_path):
    msg = _error(_yaml(tmp_path, "- image\n- resolution\n"))
    assert "bad_map.yaml" in msg
    assert "mapping" in msg
    assert "list" in msg


def test_empty_yaml(tmp_path):
    msg = _error(_yaml(tmp_path, "# nothing\n"))
    assert "bad_map.yaml" in msg
    assert "empty" in msg


@pytest.mark.parametrize("key", ["image", "resolution", "origin"])
def test_missing_required_key(tmp_path, key):
    doc = yaml.safe_load(ROS_YAML)
    del doc[key]
    msg = _error(_yaml(tmp_path, yaml.safe_dump(doc)))
    assert msg.startswith(f"{tmp_path / 'bad_map.yaml'}: {key}: ")
    assert "missing" in msg


def test_unknown_key_suggests_close_match(tmp_path):
    text = ROS_YAML.replace("resolution:", "resolutoin:")
    msg = _error(_yaml(tmp_path, text))
    assert "bad_map.yaml" in msg
    assert "resolutoin" in msg
    assert "did you mean 'resolution'?" in msg


def test_unknown_key_without_match(tmp_path):
    msg = _error(_yaml(tmp_path, ROS_YAML + "colour: red\n"))
    assert "bad_map.yaml: colour: unknown key" in msg
    assert "did you mean" not in msg


@pytest.mark.parametrize(
    ("replace", "field", "words"),
    [
        ("origin: [-20.000000, -20.000000, 0.000000]", "origin", "rotated maps are not supported"),
        ("origin: [-20.000000, -20.000000, 0.000000]", "origin", "0.5"),
        ("free_thresh: 0.196", "free_thresh", "must be below occupied_thresh"),
        ("negate: 0", "negate", "negate must be 0, 1"),
        ("resolution: 0.100000", "resolution", "greater than 0"),
        ("image: map.pgm", "image", "at least 1"),
        ("occupied_thresh: 0.65", "occupied_thresh", "less than or equal to 1"),
    ],
)
def test_invalid_values(tmp_path, replace, field, words):
    bad = {
        "origin": "origin: [-20.0, -20.0, 0.5]",
        "free_thresh": "free_thresh: 0.65",
        "negate": "negate: 2",
        "resolution": "resolution: -0.1",
        "image": "image: ''",
        "occupied_thresh": "occupied_thresh: 1.5",
    }[field]
    msg = _error(_yaml(tmp_path, ROS_YAML.replace(replace, bad)))
    assert msg.startswith(f"{tmp_path / 'bad_map.yaml'}: {field}: ")
    assert words in msg


def test_bad_mode_and_short_origin(tmp_path):
    msg = _error(_yaml(tmp_path, ROS_YAML + "mode: fancy\n"))
    assert "bad_map.yaml: mode: " in msg
    assert "trinary" in msg
    msg = _error(_yaml(tmp_path, ROS_YAML.replace("0.000000]", "]").replace(", ]", "]")))
    assert "bad_map.yaml: origin: " in msg


def test_rotated_origin_rejected_in_code():
    with pytest.raises(ValueError, match="rotated maps are not supported"):
        MapMetadata(image="m.pgm", resolution=0.1, origin=(0.0, 0.0, 1.57))


def test_image_not_found_names_looked_for_path(tmp_path):
    p = tmp_path / "bad_map.yaml"
    p.write_text(ROS_YAML.replace("map.pgm", "missing.pgm"))
    msg = _error(p)
    assert "bad_map.yaml: image: " in msg
    assert str(tmp_path / "missing.pgm") in msg


def test_corrupt_image(tmp_path):
    p = _yaml(tmp_path, ROS_YAML)
    (tmp_path / "map.pgm").write_bytes(b"this is not an image")
    msg = _error(p)
    assert "bad_map.yaml: image: cannot read image" in msg
    assert "map.pgm" in msg


def test_truncated_png(tmp_path):
    p = _yaml(tmp_path, ROS_YAML.replace("map.pgm", "map.png"))
    Image.fromarray(np.random.default_rng(0).integers(0, 255, (64, 64), dtype=np.uint8)).save(
        tmp_path / "map.png"
    )
    data = (tmp_path / "map.png").read_bytes()
    (tmp_path / "map.png").write_bytes(data[: len(data) // 2])
    msg = _error(p)
    assert "bad_map.yaml: image: cannot read image" in msg


def test_unsupported_image_mode(tmp_path):
    p = _yaml(tmp_path, ROS_YAML.replace("map.pgm", "map.tiff"))
    Image.fromarray(np.zeros((2, 2), dtype=np.float32), mode="F").save(tmp_path / "map.tiff")
    msg = _error(p)
    assert "bad_map.yaml: image: " in msg
    assert "unsupported image mode 'F'" in msg
