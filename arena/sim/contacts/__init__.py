"""TEMPORARY reference version (lead replaces at merge): exact-footprint contacts.

Re-exports :class:`ContactBank` and :class:`Footprint` for the engine. Today's contact
functions still live in ``arena/sim/native2d/collisions.py``, whose package imports the engine,
which imports this package: to enter through the engine without that cycle, the module is
loaded here by its file under its own name (helper C's move of the file into this package
removes the need).
"""

import importlib.util
import sys
from pathlib import Path

_NAME = "arena.sim.native2d.collisions"
if _NAME not in sys.modules:
    _spec = importlib.util.spec_from_file_location(
        _NAME, Path(__file__).parent.parent / "native2d" / "collisions.py"
    )
    assert _spec is not None
    assert _spec.loader is not None
    _mod = importlib.util.module_from_spec(_spec)
    sys.modules[_NAME] = _mod
    _spec.loader.exec_module(_mod)

from arena.sim.contacts.bank import ContactBank  # noqa: E402
from arena.sim.native2d.collisions import Footprint  # noqa: E402

__all__ = ["ContactBank", "Footprint"]
