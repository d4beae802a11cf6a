import sys

import pytest
from pydantic import BaseModel, ConfigDict, Field

from arena.core import registry as registry_module
from arena.core.errors import ConfigError, UnknownNameError
from arena.core.registry import Registry, all_registries


def make_registry(kind: str) -> Registry:
    reg = Registry(kind)

    @reg.register("social_force", tags=("default", "sfm"))
    class SocialForce:
        """Helbing's social force."""

        class Params(BaseModel):
            model_config = ConfigDict(frozen=True, extra="forbid")
            relaxation_time: float = Field(0.5, gt=0)

        def __init__(self, params, extra=None):
            self.params = params
            self.extra = extra

    @reg.register("orca")
    class Orca:
        def __init__(self):
            self.built = True

    return reg


def test_build_validates_params_and_passes_args():
    reg = make_registry("test kind a")
    obj = reg.build({"type": "social_force", "relaxation_time": 0.7}, extra=3)
    assert obj.params.relaxation_time == 0.7
    assert obj.extra == 3
    assert reg.build("social_force").params.relaxation_time == 0.5
    assert reg.build({"type": "orca"}).built


def test_unknown_name_suggests_close_match():
    reg = make_registry("test kind b")
    with pytest.raises(UnknownNameError) as info:
        reg.build({"type": "socal_force"}, source="exp.yaml", path="crowd")
    msg = str(info.value)
    assert "exp.yaml" in msg
    assert "crowd.type" in msg
    assert "did you mean 'social_force'" in msg
    assert "orca" in msg  # lists the known names


def test_duplicate_name_is_rejected():
    reg = make_registry("test kind c")

    class Other:
        pass

    with pytest.raises(ValueError, match="duplicate"):
        reg.add("orca", Other)


def test_duplicate_registry_kind_is_rejected():
    make_registry("test kind d")
    with pytest.raises(ValueError, match="already exists"):
        Registry("test kind d")


def test_params_errors_name_file_and_key_path():
    reg = make_registry("test kind e")
    with pytest.raises(ConfigError) as info:
        reg.build({"type": "social_force", "relaxation_tme": 1.0}, source="a.yaml", path="crowd")
    msg = str(info.value)
    assert msg.startswith("a.yaml: crowd.relaxation_tme")
    assert "unknown key" in msg
    with pytest.raises(ConfigError, match="greater than 0"):
        reg.build({"type": "social_force", "relaxation_time": -1})


def test_params_on_plugin_without_params_and_missing_type():
    reg = make_registry("test kind f")
    with pytest.raises(ConfigError, match="takes no parameters"):
        reg.build({"type": "orca", "radius": 1})
    with pytest.raises(ConfigError, match="missing 'type'"):
        reg.build({"radius": 1}, path="crowd")
    with pytest.raises(ConfigError, match="expected a mapping"):
        reg.build(42)  # type: ignore[arg-type]


def test_names_tags_and_summary():
    reg = make_registry("test kind g")
    assert reg.names() == ["orca", "social_force"]
    assert reg.names(tag="sfm") == ["social_force"]
    assert "orca" in reg and "nope" not in reg
    assert len(reg) == 2
    assert reg.entry("social_force").summary == "Helbing's social force."
    assert all_registries()["test kind g"] is reg


def test_entry_points_are_loaded(monkeypatch):
    import arena.core.registry as registry_module

    class FakeEP:
        name = "third"

        def load(self):
            class Third:
                """A third-party plugin."""

            return Third

    monkeypatch.setattr(
        registry_module, "_entry_points", lambda group: [FakeEP()] if group == "x.y" else []
    )
    reg = Registry("test kind h", entry_points="x.y")
    assert reg.names() == ["third"]
    assert reg.entry("third").tags == ("third_party",)


def _builtin_module(tmp_path, monkeypatch, kind: str, name: str, registers: bool) -> str:
    # the registry made by the test is dropped afterwards: `arena plugins` lists every registry
    monkeypatch.setattr(registry_module, "_ALL", dict(all_registries()))
    module = f"arena_test_builtin_{name}"
    body = (
        "from arena.core.registry import all_registries\n"
        f"REG = all_registries()[{kind!r}]\n"
        "class Model:\n"
        "    '''A lazily imported built-in.'''\n"
    )
    if registers:
        body += f"REG.add({name!r}, Model)\n"
    (tmp_path / f"{module}.py").write_text(body)
    monkeypatch.syspath_prepend(str(tmp_path))
    return module


def test_builtin_names_are_known_before_their_module_is_imported(tmp_path, monkeypatch):
    module = _builtin_module(tmp_path, monkeypatch, "test kind lazy a", "walker", registers=True)
    reg = Registry("test kind lazy a", builtins={"walker": module})
    assert reg.names() == ["walker"] and "walker" in reg and len(reg) == 1
    assert module not in sys.modules  # listing and membership import nothing
    assert reg.get("walker").__module__ == module  # the first lookup imports it
    assert module in sys.modules


def test_a_plugin_taking_a_builtin_name_is_a_duplicate(tmp_path, monkeypatch):
    module = _builtin_module(tmp_path, monkeypatch, "test kind lazy b", "spinny", registers=True)
    reg = Registry("test kind lazy b", builtins={"spinny": module})

    class Mine:
        pass

    with pytest.raises(ValueError, match=f"duplicate test kind lazy b name 'spinny': already "
                                         f"registered by {module}.Model"):
        reg.add("spinny", Mine)


def test_a_builtin_module_that_does_not_register_its_name_fails_loudly(tmp_path, monkeypatch):
    module = _builtin_module(tmp_path, monkeypatch, "test kind lazy c", "ghost", registers=False)
    reg = Registry("test kind lazy c", builtins={"ghost": module})
    with pytest.raises(RuntimeError, match=f"{module} is declared to register test kind lazy c "
                                           "'ghost', did not"):
        reg.get("ghost")


def test_an_alias_resolves_to_its_builtin_everywhere(tmp_path, monkeypatch):
    module = _builtin_module(tmp_path, monkeypatch, "test kind alias a", "ambler", registers=True)
    reg = Registry("test kind alias a", builtins={"ambler": module}, aliases={"stroll": "ambler"})
    # an alias is not a second plugin: listed once under its target, shown by aliases()
    assert reg.names() == ["ambler"] and len(reg) == 1
    assert reg.aliases() == {"stroll": "ambler"}
    assert "stroll" in reg and reg.resolve("stroll") == "ambler" and reg.resolve("x") == "x"
    assert module not in sys.modules  # knowing the alias imports nothing
    assert reg.get("stroll") is reg.get("ambler")
    assert reg.entry("stroll").name == "ambler"
    assert isinstance(reg.build("stroll"), reg.get("ambler"))
    assert "did you mean 'stroll'" in reg.unknown_message("strol")


def test_an_alias_must_name_a_builtin_and_cannot_be_taken(tmp_path, monkeypatch):
    module = _builtin_module(tmp_path, monkeypatch, "test kind alias b", "ambler", registers=False)
    with pytest.raises(ValueError, match="alias 'stroll' -> 'runner': an alias must name a"):
        Registry("test kind alias b", builtins={"ambler": module}, aliases={"stroll": "runner"})
    with pytest.raises(ValueError, match="alias 'ambler' -> 'ambler'"):
        Registry("test kind alias c", builtins={"ambler": module}, aliases={"ambler": "ambler"})
    reg = Registry("test kind alias d", builtins={"ambler": module}, aliases={"stroll": "ambler"})

    class Mine:
        pass

    with pytest.raises(ValueError, match="duplicate test kind alias d name 'stroll': it is an "
                                         "alias of 'ambler'"):
        reg.add("stroll", Mine)
