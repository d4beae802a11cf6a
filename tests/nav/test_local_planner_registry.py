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


def test_rosnav_is_arenas_name_for_rosnav_rl() -> None:
    # Arena-Rosnav's contest files (planners.yaml, inter.yaml) name the learned planner `rosnav`
    from arena.learn.planners.learned import LearnedPlanner

    assert LOCAL_PLANNERS.aliases()["rosnav"] == "rosnav_rl"
    assert LOCAL_PLANNERS.get("rosnav") is LearnedPlanner
    assert "rosnav" in LOCAL_PLANNERS and "rosnav" not in LOCAL_PLANNERS.names()
    assert isinstance(LOCAL_PLANNERS.build({"type": "rosnav"}), LearnedPlanner)  # packaged weights


def test_an_arena_contest_naming_rosnav_plans_its_jobs() -> None:
    from arena.config.loader import load_config
    from arena.eval.runner import plan_jobs
    from arena.tasks.suite import ContestFile, load_suite

    # Arena's inter.yaml, abridged: rosnav behind Arena's social intermediate planners
    contest = ContestFile.model_validate({"contestants": [
        {"name": "rosnav-polite", "local_planner": "rosnav", "inter_planner": "polite"},
        {"name": "rosnav-aggressive", "local_planner": "rosnav", "inter_planner": "aggressive"},
    ]})
    jobs = plan_jobs(load_suite("barn", scale_episodes=0.02), contest, load_config())
    assert [(j.local_planner, j.inter_planner) for j in jobs] == [
        ("rosnav", "polite"), ("rosnav", "aggressive")]
    nav = [j.config["navigation"] for j in jobs]
    assert [n["local_planner"]["type"] for n in nav] == ["rosnav", "rosnav"]
    assert [n["intermediate_planner"]["type"] for n in nav] == ["polite", "aggressive"]
