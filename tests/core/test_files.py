"""The shared reader of user files: legal inputs load, malformed ones are refused by structure."""

from __future__ import annotations

import numpy as np
import pytest

from arena.core import files
from arena.core.errors import ConfigError


def _bomb(levels: int, width: int = 9) -> str:
    """A YAML alias bomb expanding to ``width ** levels`` strings from ``levels`` lines."""
    lines = [f"l0: &l0 [{', '.join(['x'] * width)}]"]
    for i in range(1, levels):
        lines.append(f"l{i}: &l{i} [{', '.join([f'*l{i - 1}'] * width)}]")
    return "\n".join(lines) + "\n"


def test_alias_bomb_is_refused_by_counting_shared_nodes_once():
    # 9**40 values: were the document expanded, this test would never end; the check walks
    # the 40 * 10 distinct nodes only.
    with pytest.raises(ConfigError, match=r"x\.yaml: .*expands to more than 1,000,000 values"):
        files.parse_yaml(_bomb(40), source="x.yaml")


def test_aliases_within_the_limit_are_legal_and_shared():
    data = files.parse_yaml(_bomb(3, width=3), source="x.yaml")  # 27 values
    assert data["l2"][0][0] == ["x", "x", "x"]
    base = "base: &b {vmax: 1.0, radius: 0.3}\nped:\n  <<: *b\n  vmax: 2.0\n"
    assert files.parse_yaml(base)["ped"] == {"vmax": 2.0, "radius": 0.3}  # merge key overridden


def test_nesting_limit_is_exact():
    ok = "a: " + "[" * (files.MAX_DEPTH - 1) + "]" * (files.MAX_DEPTH - 1)
    assert files.parse_yaml(ok) is not None
    deep = "a: " + "[" * files.MAX_DEPTH + "]" * files.MAX_DEPTH
    with pytest.raises(ConfigError, match="nested deeper than 64 levels"):
        files.parse_yaml(deep)
    assert files.parse_json("[" * files.MAX_DEPTH + "]" * files.MAX_DEPTH) is not None
    with pytest.raises(ConfigError, match="nested deeper than 64 levels"):
        files.parse_json("[" * (files.MAX_DEPTH + 1) + "]" * (files.MAX_DEPTH + 1))


def test_duplicate_keys_are_errors_with_their_line():
    with pytest.raises(ConfigError, match=r"line 3, column 3: duplicate key 'b'"):
        files.parse_yaml("a:\n  b: 1\n  b: 2\n")
    with pytest.raises(ConfigError, match="duplicate key 'b'"):
        files.parse_json('{"a": {"b": 1, "b": 2}}')
    assert files.parse_yaml("a: {b: 1}\nc: {b: 2}\n") == {"a": {"b": 1}, "c": {"b": 2}}


def test_text_encodings(tmp_path):
    p = tmp_path / "bom.yaml"
    p.write_bytes("\ufeffseed: 1\n".encode())  # a UTF-8 byte-order mark is legal and skipped
    assert files.read_yaml(p) == {"seed": 1}
    p.write_bytes("seed: 1\n".encode("utf-16-le"))  # no BOM: NUL bytes give it away
    with pytest.raises(ConfigError, match="NUL byte"):
        files.read_text(p)
    p.write_bytes("seed: 1\n".encode("utf-32"))
    with pytest.raises(ConfigError, match="UTF-32 text; save it as UTF-8"):
        files.read_text(p)
    p.write_bytes(b"seed: \xe9\n")  # latin-1
    with pytest.raises(ConfigError, match=r"not UTF-8 text \(byte 0xe9 at offset 6\)"):
        files.read_text(p)


def test_make_dir(tmp_path):
    assert files.make_dir(tmp_path / "a" / "b").is_dir()
    (tmp_path / "f").write_text("x")
    with pytest.raises(ConfigError, match="f: output folder: exists and is not a folder"):
        files.make_dir(tmp_path / "f")
    with pytest.raises(ConfigError, match="cannot create it"):
        files.make_dir(tmp_path / "f" / "sub")
    with pytest.raises(ConfigError, match="cannot create it"):
        files.make_dir(tmp_path / ("n" * 300))


def test_read_npz(tmp_path):
    np.savez(tmp_path / "ok.npz", w=np.arange(3.0))
    assert files.read_npz(tmp_path / "ok.npz", ["w"])["w"].tolist() == [0.0, 1.0, 2.0]
    with pytest.raises(ConfigError, match=r"lacks the arrays \['v'\]"):
        files.read_npz(tmp_path / "ok.npz", ["v"])
    np.savez(tmp_path / "obj.npz", w=np.array([{"a": 1}], dtype=object))
    with pytest.raises(ConfigError, match="pickled Python objects, which are never loaded"):
        files.read_npz(tmp_path / "obj.npz", ["w"])
