"""Reading the text files users hand us (YAML, JSON) and making output folders, safely.

Every config, robot, suite, contest, map.yaml and scenario file is read through here, so that
one set of rules holds everywhere and each failure is a one-line :class:`ConfigError` naming the
file:

* Text is UTF-8 (a UTF-8 byte-order mark is skipped). UTF-16/32 text, binary data, NUL bytes
  and files over :data:`MAX_FILE_BYTES` are refused with what was found.
* YAML is parsed safely (no Python objects), a key given twice in one mapping is an error
  (PyYAML would silently keep the last), nesting deeper than :data:`MAX_DEPTH` is refused while
  the document is composed, and a document whose aliases expand to more than
  :data:`MAX_NODES` values (the "billion laughs" bomb: a few lines that expand to 10⁹ values)
  or that refers to itself is refused before anything is built: the size is counted over the
  node graph, each shared node once, so the refusal costs as little as reading the file.
* JSON: the same depth limit and duplicate-key rule.
"""

from __future__ import annotations

import json
import os
import zipfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from arena.core.errors import ConfigError

MAX_DEPTH = 64
"""Deepest nesting of lists/mappings accepted in a YAML or JSON file (ours need < 10)."""
MAX_NODES = 1_000_000
"""Most values a YAML document may expand to (aliases counted at every use)."""
MAX_FILE_BYTES = 64 * 2**20
"""Largest text file read (64 MiB; the largest packaged scenario is well under 1 MiB)."""

_BOMS = (
    (b"\x00\x00\xfe\xff", "UTF-32"),
    (b"\xff\xfe\x00\x00", "UTF-32"),
    (b"\xfe\xff", "UTF-16"),
    (b"\xff\xfe", "UTF-16"),
)


def read_text(path: str | os.PathLike[str], *, what: str = "file") -> str:
    """The content of a UTF-8 text file.

    Raises:
        ConfigError: missing, a folder or device, too large, not UTF-8 text (naming the
            encoding found, or the first bad byte), or unreadable.
    """
    p = Path(path)
    source = str(p)
    try:  # exists() itself raises for a name too long
        if not p.exists():
            raise ConfigError(f"{what} not found", source=source)
        if p.is_dir():
            raise ConfigError(f"expected a {what}, found a folder", source=source)
        if not p.is_file():
            raise ConfigError(f"expected a {what}, found a device or pipe", source=source)
        if p.stat().st_size > MAX_FILE_BYTES:
            raise ConfigError(
                f"{what} is larger than {MAX_FILE_BYTES // 2**20} MiB", source=source
            )
        data = p.read_bytes()
    except OSError as e:
        raise ConfigError(f"cannot read the {what}: {e.strerror or e}", source=source) from None
    return decode_text(data, source=source)


def decode_text(data: bytes, *, source: str | None = None) -> str:
    """Decode a file's bytes as UTF-8 text (see :func:`read_text` for the rules)."""
    for bom, name in _BOMS:
        if data.startswith(bom):
            raise ConfigError(f"the file is {name} text; save it as UTF-8", source=source)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        raise ConfigError(
            f"not UTF-8 text (byte 0x{data[e.start]:02x} at offset {e.start}); "
            "a binary file, or text in another encoding (save it as UTF-8)",
            source=source,
        ) from None
    if "\0" in text:
        raise ConfigError(
            f"not a text file (NUL byte at offset {text.index(chr(0))})", source=source
        )
    return text


# -- YAML ---------------------------------------------------------------------------------------
class StrictLoader(yaml.SafeLoader):  # type: ignore[misc]  # PyYAML ships no type stubs
    """PyYAML's safe loader with duplicate keys, deep nesting and alias bombs refused."""

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self._depth = 0

    def compose_node(self, parent: Any, index: Any) -> Any:  # noqa: D102
        self._depth += 1
        try:
            if self._depth > MAX_DEPTH:
                raise yaml.composer.ComposerError(
                    None, None, f"nested deeper than {MAX_DEPTH} levels",
                    self.peek_event().start_mark,
                )
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1

    def get_single_node(self) -> Any:  # noqa: D102
        node = super().get_single_node()
        if node is not None:
            _check_expansion(node)
        return node


def _check_expansion(root: yaml.Node) -> None:
    """Refuse a node graph that expands to more than MAX_NODES values or MAX_DEPTH levels.

    Aliases make the graph a DAG (or a cycle): each node's expanded size and depth is computed
    once, from its children's, iteratively, so a bomb costs its number of distinct nodes.
    """
    size: dict[int, int] = {}
    depth: dict[int, int] = {}
    on_path: set[int] = set()
    stack: list[tuple[yaml.Node, bool]] = [(root, False)]

    def children(node: yaml.Node) -> list[yaml.Node]:
        if isinstance(node, yaml.SequenceNode):
            return list(node.value)
        if isinstance(node, yaml.MappingNode):
            return [n for pair in node.value for n in pair]
        return []

    while stack:
        node, done = stack.pop()
        key = id(node)
        if done:
            on_path.discard(key)
            kids = children(node)
            size[key] = min(MAX_NODES + 1, 1 + sum(size[id(k)] for k in kids))
            depth[key] = 1 + max((depth[id(k)] for k in kids), default=0)
            if size[key] > MAX_NODES:
                raise yaml.composer.ComposerError(
                    None, None,
                    f"the document expands to more than {MAX_NODES:,} values through its "
                    "aliases (*name); refused", node.start_mark,
                )
            if depth[key] > MAX_DEPTH:
                raise yaml.composer.ComposerError(
                    None, None, f"nested deeper than {MAX_DEPTH} levels through its aliases",
                    node.start_mark,
                )
            continue
        if key in size:
            continue
        if key in on_path:
            raise yaml.composer.ComposerError(
                None, None, "an alias refers to the node that contains it (a cycle)",
                node.start_mark,
            )
        on_path.add(key)
        stack.append((node, True))
        stack.extend((k, False) for k in children(node) if id(k) not in size)


def _mapping_no_duplicates(loader: StrictLoader, node: yaml.MappingNode) -> dict[Any, Any]:
    seen: set[Any] = set()
    for key_node, _ in node.value:
        if key_node.tag == "tag:yaml.org,2002:merge":
            continue  # ``<<: *base`` merges keys that the mapping's own keys then override
        key = loader.construct_object(key_node, deep=True)
        try:
            duplicate = key in seen
        except TypeError:
            raise yaml.constructor.ConstructorError(
                None, None, "found an unhashable key (a list or mapping)", key_node.start_mark
            ) from None
        if duplicate:
            raise yaml.constructor.ConstructorError(
                None, None, f"duplicate key {key!r}", key_node.start_mark
            )
        seen.add(key)
    out: dict[Any, Any] = loader.construct_mapping(node, deep=True)  # merges <<, last wins
    return out


StrictLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _mapping_no_duplicates)


def yaml_problem(e: yaml.YAMLError) -> str:
    """One line from a PyYAML error: the problem with its 1-based line and column."""
    mark = getattr(e, "problem_mark", None) or getattr(e, "context_mark", None)
    problem = getattr(e, "problem", None) or str(e).splitlines()[0]
    where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
    return f"malformed YAML{where}: {problem}"


def parse_yaml(text: str, *, source: str | None = None) -> Any:
    """Parse YAML text with :class:`StrictLoader`; errors name ``source``, line and column."""
    try:
        return yaml.load(text, Loader=StrictLoader)
    except yaml.YAMLError as e:
        raise ConfigError(yaml_problem(e), source=source) from None


def read_yaml(path: str | os.PathLike[str], *, what: str = "file") -> Any:
    """Read and parse a YAML file of any shape (see the module docstring for the rules)."""
    return parse_yaml(read_text(path, what=what), source=str(path))


# -- JSON ---------------------------------------------------------------------------------------
def _pairs_no_duplicates(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in pairs:
        if key in out:
            raise ValueError(f"duplicate key {key!r}")
        out[key] = value
    return out


def _json_depth(data: Any) -> int:
    deepest, stack = 0, [(data, 1)]
    while stack:
        value, d = stack.pop()
        if isinstance(value, dict | list):
            deepest = max(deepest, d)
            if d > MAX_DEPTH:
                break
            stack.extend((v, d + 1) for v in (value.values() if isinstance(value, dict) else value))
    return deepest


def parse_json(text: str, *, source: str | None = None) -> Any:
    """Parse JSON text: duplicate keys and nesting deeper than :data:`MAX_DEPTH` are errors."""
    try:
        data = json.loads(text, object_pairs_hook=_pairs_no_duplicates)
    except json.JSONDecodeError as e:
        raise ConfigError(
            f"malformed JSON at line {e.lineno}, column {e.colno}: {e.msg}", source=source
        ) from None
    except ValueError as e:  # the duplicate-key hook
        raise ConfigError(f"malformed JSON: {e}", source=source) from None
    except RecursionError:  # deeper than the interpreter's stack: surely past MAX_DEPTH
        raise ConfigError(f"nested deeper than {MAX_DEPTH} levels", source=source) from None
    if _json_depth(data) > MAX_DEPTH:
        raise ConfigError(f"nested deeper than {MAX_DEPTH} levels", source=source)
    return data


def read_json(path: str | os.PathLike[str], *, what: str = "file") -> Any:
    """Read and parse a JSON file (see :func:`parse_json`)."""
    return parse_json(read_text(path, what=what), source=str(path))


# -- numpy archives -----------------------------------------------------------------------------
def read_npz(
    path: str | os.PathLike[str], required: Sequence[str], *, what: str = "weights file"
) -> dict[str, np.ndarray]:
    """Every array of an ``.npz`` archive, read without unpickling anything.

    Args:
        path: the file.
        required: array names that must be present.
        what: what the file is, for messages.

    Raises:
        ConfigError: missing file, not an ``.npz`` archive, pickled (object) arrays, a missing
            array, or non-finite numbers in a numeric array.
    """
    p = Path(path)
    source = str(p)
    try:
        if not p.is_file():
            raise ConfigError(f"{what} not found", source=source)
        with p.open("rb") as f:
            magic = f.read(6)
        if not magic.startswith(b"PK"):  # an .npz is a zip archive
            kind = "a single .npy array" if magic == b"\x93NUMPY" else "not a zip archive"
            raise ConfigError(f"not an .npz archive ({kind}); expected a {what}", source=source)
        with np.load(p, allow_pickle=False) as z:
            arrays = {k: np.asarray(z[k]) for k in z.files}
    except ValueError as e:
        text = "holds pickled Python objects, which are never loaded" if "pickle" in str(e) \
            else f"not a readable .npz archive ({e})"
        raise ConfigError(f"{text}; expected a {what}", source=source) from None
    except (OSError, EOFError, zipfile.BadZipFile, KeyError) as e:
        raise ConfigError(f"not a readable .npz archive ({e}); expected a {what}",
                          source=source) from None
    missing = [k for k in required if k not in arrays]
    if missing:
        raise ConfigError(
            f"lacks the arrays {missing} (has {sorted(arrays)}); not a {what}", source=source
        )
    for k, a in arrays.items():
        if a.dtype.kind in "fc" and not np.all(np.isfinite(a)):
            raise ConfigError(f"array {k!r} holds NaN or infinite values", source=source)
    return arrays


# -- output folders -----------------------------------------------------------------------------
def make_dir(path: str | os.PathLike[str], *, what: str = "output folder") -> Path:
    """Create a folder (and its parents) to write into, or raise a one-line error.

    Raises:
        ConfigError: the path is an existing file (``/dev/null``), a name is too long, or the
            folder cannot be created (permissions, read-only file system ...).
    """
    p = Path(path)
    try:  # exists() itself raises for a name too long
        if p.exists() and not p.is_dir():
            raise ConfigError(f"{what}: exists and is not a folder", source=str(p))
        p.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise ConfigError(f"{what}: cannot create it: {e.strerror or e}", source=str(p)) from None
    return p


__all__ = [
    "MAX_DEPTH",
    "MAX_FILE_BYTES",
    "MAX_NODES",
    "StrictLoader",
    "decode_text",
    "make_dir",
    "parse_json",
    "parse_yaml",
    "read_json",
    "read_npz",
    "read_text",
    "read_yaml",
    "yaml_problem",
]
