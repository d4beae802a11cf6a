"""The crowd-model registry declares its built-in models by name (imported when first named)."""

import subprocess
import sys

from arena.crowd.base import CROWD_MODELS


def test_every_builtin_model_is_declared_with_the_module_that_registers_it():
    # entries() imports every declared module; a model registered by a module of
    # arena.crowd.models but missing from the declaration would be unreachable by name
    declared = CROWD_MODELS.builtins
    for entry in CROWD_MODELS.entries():
        module = entry.obj.__module__
        if entry.name in declared:  # the declared module, or a module of that package
            assert module == declared[entry.name] or module.startswith(declared[entry.name] + ".")
        else:
            assert not module.startswith("arena."), f"{entry.name} ({module}) is not declared"


def test_loading_a_config_imports_only_the_crowd_model_it_names():
    code = (
        "import sys\n"
        "from arena.config.loader import load_config\n"
        "load_config(overrides=['crowd.type=waypoint_walker'])\n"
        "print(' '.join(sorted(m for m in sys.modules if m.startswith('arena.crowd.models.'))))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    loaded = out.stdout.split()
    assert "arena.crowd.models.walker" in loaded
    # orca comes with the orca local planner (arena.plugins lists every planner); the numba
    # social-force models, the learned one and the panic models are not compiled
    for other in ("pysocial", "pedsim", "evacuation", "bonding", "deep_social_force", "spinny"):
        assert f"arena.crowd.models.{other}" not in loaded
