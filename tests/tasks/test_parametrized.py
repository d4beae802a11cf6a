import numpy as np
import pytest

from arena.core.errors import ConfigError
from arena.robots.presets import load_robot
from arena.scene.episode import episode_digest
from arena.tasks.config import TaskConfig
from arena.tasks.generator import TaskGenerator
from arena.tasks.obstacle_modes.parametrized import DEFAULT_FILE, load_parametrized

ROOM = {"type": "empty", "width": 16.0, "height": 12.0}

ATTRIBUTES = """<?xml version="1.0"?>
<random>
  <static>
    <obstacle name="s" min="1" max="2" model="shelf"/>
    <obstacle name="t" min="0" max="1" model="table"/>
  </static>
  <interactive>
    <obstacle name="c" min="1" max="1" model="chair"/>
  </interactive>
  <dynamic>
    <obstacle name="kids" min="2" max="3" type="child" model="actor1"/>
    <obstacle name="old" min="1" max="2" type="human/elder" model="actor2"/>
  </dynamic>
</random>
"""

ELEMENTS = """<random>
  <static>
    <obstacle name="s"><min>1</min><max>2</max><model>shelf</model></obstacle>
    <obstacle name="t"><min>0</min><max>1</max><model>table</model></obstacle>
  </static>
  <interactive>
    <obstacle name="c"><min>1</min><max>1</max><model>chair</model></obstacle>
  </interactive>
  <dynamic>
    <obstacle name="kids"><min>2</min><max>3</max><type>child</type><model>actor1</model>
    </obstacle>
    <obstacle name="old"><min>1</min><max>2</max><type>human/elder</type></obstacle>
  </dynamic>
</random>
"""


def write(tmp_path, text, name="p.xml"):
    f = tmp_path / name
    f.write_text(text)
    return f


def gen(file=None, seed=0, map_spec=ROOM):
    obstacles = {"type": "parametrized", **({"file": str(file)} if file else {})}
    cfg = TaskConfig.model_validate({"obstacles": obstacles})
    return TaskGenerator(cfg, map_spec=map_spec, robots=[load_robot("burger")], seed=seed)


@pytest.mark.parametrize("text", [ATTRIBUTES, ELEMENTS], ids=["attributes", "elements"])
def test_attributes_and_elements_read_alike(tmp_path, text):
    entries = load_parametrized(write(tmp_path, text))
    got = [(e.section, e.name, e.min, e.max, e.model, e.kind) for e in entries]
    assert got == [
        ("static", "s", 1, 2, "shelf", 0),
        ("static", "t", 0, 1, "table", 0),
        ("interactive", "c", 1, 1, "chair", 0),
        ("dynamic", "kids", 2, 3, "actor1", 2),
        ("dynamic", "old", 1, 2, "actor1" if text is ELEMENTS else "actor2", 1),
    ]


def test_counts_within_ranges_and_dynamic_block_is_read(tmp_path):
    g = gen(write(tmp_path, ATTRIBUTES))
    n_ped, n_shelf = set(), set()
    for i in range(25):
        ep = g.episode(i)
        names = [o.name for o in ep.obstacles]
        shelves = sum(n.startswith("S_shelf_") for n in names)
        tables = sum(n.startswith("S_table_") for n in names)
        chairs = sum(n.startswith("I_chair_") for n in names)
        assert 1 <= shelves <= 2 and 0 <= tables <= 1 and chairs == 1
        assert len(set(names)) == len(names)
        kinds = ep.agents.kinds
        assert 2 <= np.sum(kinds == 2) <= 3 and 1 <= np.sum(kinds == 1) <= 2
        assert np.sum(kinds == 0) == 0
        n_ped.add(len(ep.agents))
        n_shelf.add(shelves)
    assert n_ped == {3, 4, 5} and n_shelf == {1, 2}  # every count of the ranges occurs


def test_default_file_reads_its_dynamic_block():
    entries = load_parametrized(DEFAULT_FILE)
    assert [(e.section, e.model, e.min, e.max) for e in entries] == [
        ("static", "shelf", 2, 7),
        ("dynamic", "actor1", 1, 3),
        ("dynamic", "actor2", 2, 4),
    ]
    g = gen(map_spec={"type": "world", "name": "hospital_floor"})
    counts = [len(g.episode(i).agents) for i in range(15)]
    assert min(counts) >= 3 and max(counts) <= 7 and len(set(counts)) > 1


def test_deterministic_per_seed(tmp_path):
    f = write(tmp_path, ATTRIBUTES)
    a = [episode_digest(gen(f).episode(i)) for i in range(3)]
    b = [episode_digest(gen(f).episode(i)) for i in reversed(range(3))][::-1]
    c = [episode_digest(gen(f, seed=1).episode(i)) for i in range(3)]
    assert a == b and a != c


def test_unknown_model_names_file_entry_and_known_models(tmp_path):
    f = write(tmp_path, ATTRIBUTES.replace('model="table"', 'model="sofa"'))
    with pytest.raises(ConfigError) as e:
        load_parametrized(f)
    assert e.value.source == str(f)
    assert e.value.path == "static/obstacle[2]/model"
    assert "sofa" in str(e.value) and "shelf" in str(e.value) and "table" in str(e.value)
    # Also when the mode is built from a config.
    with pytest.raises(ConfigError, match=r"static/obstacle\[2\]/model"):
        gen(f)


def test_malformed_xml_names_file_and_line(tmp_path):
    f = write(tmp_path, "<random>\n  <static>\n    <obstacle name='x'>\n  </static>\n</random>\n")
    with pytest.raises(ConfigError) as e:
        load_parametrized(f)
    assert e.value.source == str(f)
    assert e.value.path == "line 4"
    assert "malformed XML" in str(e.value)


@pytest.mark.parametrize(
    ("text", "path", "match"),
    [
        ('<random><static><obstacle min="a" model="shelf"/></static></random>',
         "static/obstacle[1]/min", "integer"),
        ('<random><static><obstacle min="3" max="1" model="shelf"/></static></random>',
         "static/obstacle[1]/max", "must not exceed"),
        ('<random><dynamic><obstacle min="1" type="robot"/></dynamic></random>',
         "dynamic/obstacle[1]/type", "unknown pedestrian type"),
        ('<random><static><obstacle min="1" max="2" model="shelf"><max>3</max></obstacle>'
         "</static></random>", "static/obstacle[1]/max", "different values"),
        ('<random><static><obstacle min="1" colour="red" model="shelf"/></static></random>',
         "static/obstacle[1]/colour", "unknown attribute"),
        ("<random><stat/></random>", "stat", "unknown block"),
        ("<tasks/>", "tasks", "root element"),
        ('<random><static><obstacle max="1" model="shelf"/></static></random>',
         "static/obstacle[1]/min", "missing"),
    ],
)
def test_bad_entries_are_located(tmp_path, text, path, match):
    with pytest.raises(ConfigError, match=match) as e:
        load_parametrized(write(tmp_path, text))
    assert e.value.path == path


def test_missing_file(tmp_path):
    with pytest.raises(ConfigError, match="not found"):
        gen(tmp_path / "nope.xml")
