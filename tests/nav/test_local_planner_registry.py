"""The local-planner registry declares its built-in planners by name (imported when first named)."""

import subprocess
import sys

from arena.nav.local_planners import LOCAL_PLANNERS


def test_every_builtin_planner_is_declared_with_the_module_that_registers_it() -> None:
    # entries() imports every declared module; a planner registered by a module of
    # arena.nav.local_planners but missing from the declaration would be unreachable by name
    declared = LOCAL_PLANNERS.builtins
    for entry in LOCAL_PLANNERS.entries():
        module = entry.obj.__module__
        if entry.name in declared:
            assert module == declared[entry.name]
        else:
            assert not module.startswith("arena.nav."), f"{entry.name} ({module}) is not declared"


def test_a_config_imports_only_the_local_planner_it_names() -> None:
    code = (
        "import sys\n"
        "from arena.config.loader import load_config\n"
        "load_config(overrides=['navigation.local_planner.type=dwa'])\n"
        "print(*sorted(m for m in sys.modules if m.startswith('arena.nav.local_planners.')))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr[-2000:]
    loaded = out.stdout.split()
    assert "arena.nav.local_planners.dwa" in loaded
    # the orca planner would compile the ORCA crowd kernels; the learned ones load torch weights
    for other in ("orca_planner", "teb", "mpc", "cohan", "crowdnav", "rlca", "learned"):
        assert f"arena.nav.local_planners.{other}" not in loaded
