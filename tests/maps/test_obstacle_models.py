import numpy as np
import pytest

from arena.core.errors import UnknownNameError
from arena.core.geometry import polygon_area
from arena.maps.obstacles import make_obstacle, obstacle_model, obstacle_models

REQUIRED = ("table", "chair", "shelf", "warehouse_shelf", "pallet_jack_1", "office_desk",
            "office_chair", "separator", "tree", "cuboid", "cylinder")


def test_library_has_every_required_model_with_sane_sizes():
    models = obstacle_models()
    for name in REQUIRED:
        m = models[name]
        assert 0.01 < polygon_area(m.polygon()) < 10.0
        assert 0.1 < m.height < 10.0


def test_footprints_match_their_declared_shape():
    box = obstacle_model("office_desk").footprint
    poly = obstacle_model("office_desk").polygon()
    assert polygon_area(poly) == pytest.approx(box.length * box.width)
    circle = obstacle_model("table")
    # 16-gon inscribed in the circle: area within 3 % of pi r^2.
    r = circle.footprint.radius
    assert polygon_area(circle.polygon()) == pytest.approx(np.pi * r * r, rel=0.03)
    assert circle.radius == pytest.approx(r)


def test_make_obstacle_places_the_footprint():
    ob = make_obstacle("d1", "office_desk", [2.0, 3.0, np.pi / 2])
    assert ob.model == "office_desk"
    xs, ys = ob.polygon[:, 0], ob.polygon[:, 1]
    # Rotated by 90 degrees: the 1.6 m width now runs along x.
    assert xs.max() - xs.min() == pytest.approx(1.6)
    assert ys.max() - ys.min() == pytest.approx(0.8)
    assert np.allclose(ob.polygon.mean(axis=0), [2.0, 3.0])


def test_unknown_model_suggests_a_name():
    with pytest.raises(UnknownNameError, match="did you mean 'office_chair'"):
        obstacle_model("ofice_chair")
