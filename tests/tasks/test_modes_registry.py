"""The task-mode registry declares its built-in modes by name (imported when first named)."""

import subprocess
import sys

from arena.tasks.base import TASK_MODES, mode_names


def test_every_builtin_mode_is_declared_with_the_module_that_registers_it():
    # entries() imports every declared module; a mode registered by a module of the package but
    # missing from the declaration would be unreachable by name
    declared = TASK_MODES.builtins
    for entry in TASK_MODES.entries():
        module = entry.obj.__module__
        if entry.name in declared:  # the declared module, or a module of that package
            assert module == declared[entry.name] or module.startswith(declared[entry.name] + ".")
        else:
            assert not module.startswith("arena."), f"{entry.name} ({module}) is not declared"


def test_mode_names_per_role():
    assert mode_names("robots") == ["explore", "guided", "random", "scenario", "zones"]
    assert mode_names("obstacles") == ["parametrized", "random", "scenario", "zones"]
    assert "benchmark" in mode_names("modules")


def test_validating_a_mode_imports_only_that_mode():
    code = (
        "import sys\n"
        "from arena.tasks.base import validate_mode\n"
        "validate_mode('robots', {'type': 'explore'})\n"
        "print(sorted(m for m in sys.modules if m.startswith('arena.tasks.')))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    loaded = out.stdout.strip()
    assert "arena.tasks.robot_modes.explore" in loaded  # (it reuses robot_modes.random)
    for other in ("robot_modes.zones", "robot_modes.scenario", "obstacle_modes.", "modules."):
        assert f"arena.tasks.{other}" not in loaded
