"""The crowd-model registry declares its built-in models by name (imported when first named)."""

import subprocess
import sys
from pathlib import Path

import pytest

import arena.core.registry as registry_module
from arena.core.errors import ConfigError
from arena.core.registry import Registry
from arena.crowd.base import CROWD_MODELS
from arena.crowd.models.orca.params import OrcaParams


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
    # the numba social-force and ORCA models (the orca local planner too, not named), the
    # learned one and the panic models are not compiled
    for other in ("pysocial", "pedsim", "evacuation", "bonding", "deep_social_force", "spinny",
                  "orca", "rvo2", "fast_social_force"):
        assert f"arena.crowd.models.{other}" not in loaded


# the models whose numba kernels live in a package's kernel modules, by the package
_KERNEL_PACKAGES = {
    "pysocial": "pysocial", "pedsim": "pedsim", "passthrough": "pedsim", "spinny": "pedsim",
    "evacuation": "evacuation", "bonding": "evacuation", "orca": "orca", "rvo2": "orca",
    "fast_social_force": "fast_social_force",
}


def test_a_config_validates_crowd_params_without_importing_the_kernels_building_imports_them():
    code = (
        "import sys\n"
        "from arena.config.loader import load_config\n"
        "from arena.crowd.base import CROWD_MODELS\n"
        "def kernels():  # a package's model, obstacles, *kernels; deep_social_force's model\n"
        "    mods = [m.split('.') for m in sys.modules if m.startswith('arena.crowd.models.')]\n"
        "    return sorted('.'.join(m) for m in mods if len(m) == 5\n"
        "                  and (m[4] in ('model', 'obstacles') or m[4].endswith('kernels'))\n"
        "                  or m[3:] == ['deep_social_force'])\n"
        "cfgs = [load_config()]\n"
        f"for name in {[*sorted(_KERNEL_PACKAGES), 'deep_social_force']!r}:\n"
        "    cfgs.append(load_config(overrides=[f'crowd.type={name}']))\n"
        "print('loaded', *kernels())\n"
        "for cfg in cfgs:\n"
        "    CROWD_MODELS.build(cfg.crowd)\n"
        "print('built', *kernels())\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr[-2000:]
    loaded, built = (line.split()[1:] for line in out.stdout.splitlines())
    assert loaded == []  # validated against each package's params.py alone
    for package in set(_KERNEL_PACKAGES.values()):  # building the model compiles its kernels
        assert f"arena.crowd.models.{package}.model" in built
        assert f"arena.crowd.models.{package}.kernels" in built
    assert "arena.crowd.models.pysocial.pair_kernels" in built
    assert "arena.crowd.models.orca.obstacles" in built
    assert "arena.crowd.models.deep_social_force" in built  # its kernels are in the module


def test_check_reports_bad_params_as_validate_does_without_building() -> None:
    spec = {"type": "pysocial", "gamma": -1.0}
    with pytest.raises(ConfigError) as checked:
        CROWD_MODELS.check(spec, source="exp.yaml", path="crowd")
    with pytest.raises(ConfigError) as validated:
        CROWD_MODELS.validate(spec, source="exp.yaml", path="crowd")
    assert str(checked.value) == str(validated.value)
    assert "crowd.gamma" in str(checked.value) and "exp.yaml" in str(checked.value)
    params = CROWD_MODELS.check({"type": "orca", "time_horizon": 3.0})
    assert isinstance(params, OrcaParams) and params.time_horizon == 3.0


def test_a_plugin_whose_params_are_not_the_declared_ones_is_refused(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "twin_params_plugin.py").write_text(
        "from pydantic import BaseModel\n"
        "from arena.core.registry import all_registries\n"
        "class Light(BaseModel):\n"
        "    x: float = 1.0\n"
        "class Twin(BaseModel):  # a second definition, kept equal by hand\n"
        "    x: float = 1.0\n"
        "@all_registries()['twin params test'].register('m')\n"
        "class Plugin:\n"
        "    Params = Twin\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    # the test registry lives in a copy of the registry table, gone after the test
    monkeypatch.setattr(registry_module, "_ALL", dict(registry_module._ALL))
    reg: Registry[object] = Registry(
        "twin params test", builtins={"m": "twin_params_plugin"},
        params={"m": "twin_params_plugin:Light"},
    )
    with pytest.raises(RuntimeError, match="Params is not the declared twin_params_plugin:Light"):
        reg.get("m")
