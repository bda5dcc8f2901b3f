"""The config loader through Python: the CLI's keys, checks and messages;
errors raise ValueError naming the key."""

import copy

import numpy as np
import pytest

import mpcontact
from conftest import REPO, mindlin_text


def base():
    return {
        "grid": {"points": 64, "spacing_um": 6.0},
        "indenter": {"radius_mm": 18.0},
        "load": {"normal_n": 20.0, "friction": 0.3},
        "sweep": {"materials": ["Fe"], "angles_deg": {"start": 0, "stop": 90, "step": 45}},
    }


def test_repository_configs_load_with_their_cases():
    cfg = mpcontact.Config.from_toml(REPO / "configs" / "quick.toml")
    assert cfg.materials == ["Cu", "Cu(111)"]
    assert cfg.grid_points == 128
    assert len(cfg.cases()) == 2 * 4 * 7
    assert cfg.cases()[0] == ("Cu", "flat", 0.0)
    heightmap = mpcontact.Config.from_toml(REPO / "configs" / "examples" / "heightmap.toml")
    assert heightmap.surfaces == ["bumps"]


def test_from_dict_equals_the_same_toml(tmp_path):
    path = tmp_path / "c.toml"
    path.write_text(mindlin_text())
    from_file = mpcontact.Config.from_toml(path)
    d = {
        "grid": {"points": 96, "spacing_um": 4.0},
        "indenter": {"radius_mm": 18.0},
        "load": {"normal_n": 20.0, "friction": 0.28571, "tangential_ratio": 0.6},
        "sweep": {"materials": ["Fe"], "surfaces": ["flat"], "angles_deg": [0.0]},
        "solver": {
            "coupling": False,
            "tolerance": 1e-10,
            "tangential_tolerance": 1e-6,
            "max_iterations": 5000,
        },
    }
    assert mpcontact.Config.from_dict(d).to_toml() == from_file.to_toml()
    # numpy numbers are numbers.
    d["grid"]["points"] = np.int64(96)
    d["load"]["normal_n"] = np.float64(20.0)
    d["sweep"]["angles_deg"] = np.array([0.0])
    assert mpcontact.Config.from_dict(d).to_toml() == from_file.to_toml()


def test_set_is_the_cli_set():
    cfg = mpcontact.Config.from_dict(base())
    cfg.set("grid.points", 128)
    cfg.set("sweep.materials", ["Cu", "Fe"])
    cfg.set("sweep.angles_deg", [0, 30.5])
    cfg.set("solver.coupling", False)
    assert cfg.grid_points == 128
    assert cfg.materials == ["Cu", "Fe"]
    assert cfg.angles_deg == [0.0, 30.5]
    assert cfg.sets == [
        "grid.points=128",
        'sweep.materials=["Cu", "Fe"]',
        "sweep.angles_deg=[0, 30.5]",
        "solver.coupling=false",
    ]
    assert "coupling = false" in cfg.to_toml()


def test_copies_are_independent():
    cfg = mpcontact.Config.from_dict(base())
    other = cfg.copy()
    deep = copy.deepcopy(cfg)
    other.set("grid.points", 32)
    assert (cfg.grid_points, other.grid_points, deep.grid_points) == (64, 32, 64)


@pytest.mark.parametrize(
    "key, value, named",
    [
        ("grid.pointz", 128, "pointz"),
        ("grid.points", "many", "points"),
        ("grid.points", 4, "grid.points"),
        ("load.normal_n", -5.0, "load.normal_n"),
        ("load.friction", -0.1, "load.friction"),
        ("load.tangential_ratio", 1.0, "gross sliding"),
        ("indenter.radius_mm", 0.0, "indenter.radius_mm"),
        ("sweep.materials", ["Unobtainium"], "Unobtainium"),
        ("sweep.materials", ["Fe", "Fe"], "sweep.materials"),
        ("run.case_timeout_s", 1e20, "run.case_timeout_s"),
        ("sweep.angles_deg", {"start": 0, "stop": 90}, "needs `step`"),
    ],
)
def test_a_bad_set_raises_value_error_naming_the_key_and_changes_nothing(key, value, named):
    cfg = mpcontact.Config.from_dict(base())
    before = cfg.to_toml()
    with pytest.raises(ValueError, match=named.replace("(", r"\(")) as e:
        cfg.set(key, value)
    assert str(e.value), "a message"
    assert cfg.to_toml() == before and cfg.sets == []


def test_bad_dicts_raise_value_error_naming_the_key():
    d = base()
    d["load"]["friction_coef"] = 0.2
    with pytest.raises(ValueError, match="friction_coef"):
        mpcontact.Config.from_dict(d)
    d = base()
    d["materials"] = {"rubber": {"isotropic": {"youngs_gpa": 0.01, "poisson": 0.6}}}
    d["sweep"]["materials"] = ["rubber"]
    with pytest.raises(ValueError, match=r"materials\.rubber.*\(-1, 0\.5\]"):
        mpcontact.Config.from_dict(d)
    d = base()
    del d["indenter"]
    with pytest.raises(ValueError, match="indenter"):
        mpcontact.Config.from_dict(d)


def test_values_without_a_toml_form_raise_type_error_naming_the_key():
    d = base()
    d["load"]["normal_n"] = None
    with pytest.raises(TypeError, match="load.normal_n"):
        mpcontact.Config.from_dict(d)
    cfg = mpcontact.Config.from_dict(base())
    with pytest.raises(TypeError, match="grid.points"):
        cfg.set("grid.points", object())


def test_bad_files_raise_value_error_with_the_cli_message(tmp_path, cli):
    import subprocess

    path = tmp_path / "bad.toml"
    path.write_text(mindlin_text().replace("friction = 0.28571", "friction = 0.28571\nfrictio = 1"))
    with pytest.raises(ValueError) as e:
        mpcontact.Config.from_toml(path)
    cli_err = subprocess.run(
        [str(cli), "check", str(path)], capture_output=True, text=True
    ).stderr
    assert "frictio" in str(e.value) and "line" in str(e.value)
    assert cli_err.strip() == "error: " + str(e.value)
    with pytest.raises(ValueError, match="cannot read config"):
        mpcontact.Config.from_toml(tmp_path / "missing.toml")


def test_unknown_names_in_solve_raise_value_error():
    cfg = mpcontact.Config.from_dict(base())
    with pytest.raises(ValueError, match="Unobtainium"):
        mpcontact.solve(cfg, material="Unobtainium")
    with pytest.raises(ValueError, match="nowhere"):
        mpcontact.solve(cfg, surface="nowhere")
