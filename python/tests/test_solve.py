"""Single solves through Python against the CLI (bit for bit), the closed
forms, and the equilibrium of the returned fields."""

import math

import numpy as np
import pytest

import mpcontact
from conftest import REPO, mindlin_text, pattern_text

# Wall-clock times: the only keys of case.json that differ between two
# identical solves.
TIMES = ("seconds", "kernel_seconds")


def without_times(d):
    return {k: v for k, v in d.items() if k not in TIMES}


def assert_same_as_cli(res, case_json, cli_dir):
    """Every key and value of case.json, and every .npy field, bit for bit."""
    assert set(res.scalars) == set(case_json)
    assert without_times(res.scalars) == without_times(case_json)
    for k, v in without_times(res.scalars).items():
        if isinstance(v, float):
            # == would let -0.0 and 0.0 pass; the bits must be the same.
            assert np.float64(v).tobytes() == np.float64(case_json[k]).tobytes(), k
    for name in mpcontact.FIELD_NAMES:
        ours = res.fields[name]
        theirs = np.load(cli_dir / f"{name}.npy")
        assert ours.tobytes() == theirs.tobytes(), name


def test_hertz_scalars_and_fields_equal_the_cli_bit_for_bit(tmp_path, cli_solve):
    path = tmp_path / "hertz.toml"
    path.write_text(mindlin_text(ratio=0.0))
    case_json, cli_dir = cli_solve(path)
    res = mpcontact.solve(mpcontact.Config.from_toml(path))
    assert_same_as_cli(res, case_json, cli_dir)
    # And it is Hertz: a within 2 cells, p_max within 2 % of p0.
    s = res.scalars
    assert abs(s["contact_radius_m"] - s["hertz_radius_m"]) < 2 * s["spacing_m"]
    assert s["p_max_pa"] == pytest.approx(s["hertz_pressure_pa"], rel=0.02)
    assert s["mu_a"] is None, "no tangential load, no μa"


def test_mindlin_scalars_and_fields_equal_the_cli_bit_for_bit(tmp_path, cli_solve):
    path = tmp_path / "mindlin.toml"
    path.write_text(mindlin_text(ratio=0.6, angle=30.0))
    case_json, cli_dir = cli_solve(path)
    res = mpcontact.solve(mpcontact.Config.from_toml(path))
    assert_same_as_cli(res, case_json, cli_dir)
    # Cattaneo–Mindlin: c = a (1 − Q/μP)^(1/3), within 3 cells.
    s = res.scalars
    c = s["contact_radius_m"] * (1 - 0.6) ** (1 / 3)
    assert abs(s["stick_radius_m"] - c) < 3 * s["spacing_m"]
    assert s["status"] == "ok"


def test_set_gives_the_cli_set_result_bit_for_bit(tmp_path, cli_solve):
    path = tmp_path / "mindlin.toml"
    path.write_text(mindlin_text())
    case_json, cli_dir = cli_solve(path, "--set", "grid.points=80", "--angle-deg", "90")
    cfg = mpcontact.Config.from_toml(path)
    cfg.set("grid.points", 80)
    res = mpcontact.solve(cfg, angle_deg=90)
    assert res.fields["p"].shape == (80, 80)
    assert_same_as_cli(res, case_json, cli_dir)


def test_anisotropic_flat_twin_k_e_equals_the_cli(tmp_path, cli_solve):
    """Cu(111) on a pattern: K_E comes from the flat twin in both."""
    path = tmp_path / "cu111.toml"
    path.write_text(pattern_text("Cu(111)", "circle-A", 30.0))
    case_json, cli_dir = cli_solve(path)
    res = mpcontact.solve(mpcontact.Config.from_toml(path))
    assert res.scalars["k_e_source"] == "flat-calibrated"
    assert_same_as_cli(res, case_json, cli_dir)


def test_fields_are_float64_n_by_n_and_in_equilibrium():
    cfg = mpcontact.Config.from_dict(_dict_config(points=64, ratio=0.6, angle=45.0))
    res = mpcontact.solve(cfg)
    assert set(res.fields) == set(mpcontact.FIELD_NAMES)
    for name, f in res.fields.items():
        assert f.dtype == np.float64 and f.shape == (64, 64), name
        assert f.flags.c_contiguous
    da = res.scalars["spacing_m"] ** 2
    p, qx, qy = res.fields["p"], res.fields["qx"], res.fields["qy"]
    # Σ p ΔA = P and Σ q ΔA = F (along 45°), to 1e-9 relative.
    assert abs(p.sum() * da - 20.0) <= 1e-9 * 20.0
    f = 0.6 * 0.28571 * 20.0
    assert abs(qx.sum() * da - f * math.cos(math.radians(45))) <= 1e-9 * f
    assert abs(qy.sum() * da - f * math.sin(math.radians(45))) <= 1e-9 * f
    stick = res.fields["stick"]
    assert set(np.unique(stick)) <= {0.0, 1.0}
    assert stick.sum() * da == pytest.approx(res.scalars["stick_area_m2"], rel=1e-12)


def test_rows_are_y():
    """Under a normal load the in-plane displacement is radial: ux is odd
    along x (columns, axis 1) and even along y (rows, axis 0); uy the
    other way round."""
    cfg = mpcontact.Config.from_dict(_dict_config(points=64, ratio=0.0))
    res = mpcontact.solve(cfg)
    ux, uy = res.fields["ux"], res.fields["uy"]
    scale = np.abs(ux).max()
    assert scale > 0
    assert np.abs(ux + ux[:, ::-1]).max() < 1e-6 * scale
    assert np.abs(ux - ux[::-1, :]).max() < 1e-6 * scale
    assert np.abs(uy + uy[::-1, :]).max() < 1e-6 * scale
    assert np.abs(uy - uy[:, ::-1]).max() < 1e-6 * scale
    assert np.abs(ux - ux[:, ::-1]).max() > 0.5 * scale


def test_a_height_array_equals_the_npy_file_route_bit_for_bit(tmp_path, cli_solve):
    rng = np.random.default_rng(7)
    n = 64
    y, x = np.mgrid[0:n, 0:n]
    h = 6.0 * np.exp(-((x - 40) ** 2 + (y - 24) ** 2) / 30.0)  # one bump, µm
    h += rng.uniform(0.0, 0.5, size=(n, n))
    np.save(tmp_path / "h.npy", h)
    path = tmp_path / "map.toml"
    path.write_text(
        pattern_text("Cu", "rough", 45.0, '[surfaces.rough]\nshape = "heightmap"\nfile = "h.npy"\n')
    )
    cfg = mpcontact.Config.from_toml(path)
    by_file = mpcontact.solve(cfg)
    by_array = mpcontact.solve(cfg, surface=h)
    # A Fortran-ordered copy is the same heights.
    by_f_array = mpcontact.solve(cfg, surface=np.asfortranarray(h))
    case_json, cli_dir = cli_solve(path)
    assert_same_as_cli(by_file, case_json, cli_dir)
    for res in (by_array, by_f_array):
        assert res.scalars["surface"] == "array"
        assert without_times({**res.scalars, "surface": "rough"}) == without_times(by_file.scalars)
        for name in mpcontact.FIELD_NAMES:
            assert res.fields[name].tobytes() == by_file.fields[name].tobytes(), name
    assert by_file.scalars["base_contact"] or by_file.scalars["contact_area_m2"] > 0


def test_bad_height_arrays_raise_value_error():
    cfg = mpcontact.Config.from_dict(_dict_config(points=64))
    with pytest.raises(ValueError, match="grid is 64 x 64"):
        mpcontact.solve(cfg, surface=np.zeros((32, 32)))
    with pytest.raises(ValueError, match="2-D"):
        mpcontact.solve(cfg, surface=np.zeros(64))
    bad = np.zeros((64, 64))
    bad[3, 5] = np.nan
    with pytest.raises(ValueError, match="height"):
        mpcontact.solve(cfg, surface=bad)


def test_solver_failures_raise_solve_error():
    # A 64² grid of 0.5 µm cells is far smaller than the ~105 µm contact.
    cfg = mpcontact.Config.from_dict(_dict_config(points=64, spacing_um=0.5))
    with pytest.raises(mpcontact.SolveError, match="edge of the domain"):
        mpcontact.solve(cfg)


def _dict_config(points=64, ratio=0.6, angle=0.0, spacing_um=None):
    return {
        "grid": {"points": points, "spacing_um": spacing_um or 384.0 / points},
        "indenter": {"radius_mm": 18.0},
        "load": {"normal_n": 20.0, "friction": 0.28571, "tangential_ratio": ratio},
        "sweep": {"materials": ["Fe"], "surfaces": ["flat"], "angles_deg": [angle]},
        "solver": {"coupling": False, "tolerance": 1e-10, "tangential_tolerance": 1e-6},
    }


def assert_history_as_cli(h, cli_dir):
    """Python's history table against the CLI's history.csv: the same
    columns, every value the same bits."""
    lines = (cli_dir / "history.csv").read_text().splitlines()
    header = lines[0].split(",")
    assert list(h) == header
    assert len(h["step"]) == len(lines) - 1
    for k, name in enumerate(header):
        cli_col = [line.split(",")[k] for line in lines[1:]]
        if name == "converged":
            assert [str(v).lower() for v in h[name]] == cli_col
        else:
            # The CLI writes shortest round-trip digits: parsing gives the bits.
            assert np.array(cli_col, dtype=np.float64).tobytes() == h[name].astype(
                np.float64
            ).tobytes(), name


def test_a_fretting_history_equals_the_cli_table_bit_for_bit(tmp_path, cli_solve):
    path = tmp_path / "fretting.toml"
    path.write_text(
        mindlin_text(ratio=0.6)
        + "\n[history]\nfretting = { amplitude_ratio = 0.6, cycles = 1 }\nsteps_per_segment = 4\n"
    )
    case_json, cli_dir = cli_solve(path)
    res = mpcontact.solve(mpcontact.Config.from_toml(path))
    assert_same_as_cli(res, case_json, cli_dir)
    h = res.history()
    assert_history_as_cli(h, cli_dir)
    assert len(h["step"]) == 1 + 3 * 4
    # Energy per cycle positive and equal to the sum over the cycle's rows.
    s = res.scalars
    assert s["dissipated_energy_per_cycle_j"] > 0
    assert s["dissipated_energy_per_cycle_j"] == pytest.approx(
        h["dissipated_j"][5:].sum(), rel=1e-12
    )
    # Without a history, no table.
    plain = tmp_path / "plain.toml"
    plain.write_text(mindlin_text(ratio=0.6))
    assert mpcontact.solve(mpcontact.Config.from_toml(plain)).history() is None


def test_wear_along_a_fretting_path_equals_the_cli(tmp_path, cli_solve):
    # Archard wear over one cycle: the table with its worn-volume column,
    # the worn depth and the totals the same bits as the CLI's.
    path = tmp_path / "wear.toml"
    path.write_text(
        mindlin_text(ratio=0.6)
        + "\n[history]\nfretting = { amplitude_ratio = 0.6, cycles = 1 }\nsteps_per_segment = 4\n"
        + 'wear = { law = "archard", k_mm3_per_nm = 1e-5 }\n'
    )
    case_json, cli_dir = cli_solve(path)
    res = mpcontact.solve(mpcontact.Config.from_toml(path))
    assert_same_as_cli(res, case_json, cli_dir)
    h = res.history()
    assert_history_as_cli(h, cli_dir)
    worn = h["worn_volume_m3"]
    depth = res.fields["wear"]
    assert depth.tobytes() == np.load(cli_dir / "wear.npy").tobytes()
    total = res.scalars["history"]["worn_volume_m3"]
    assert total == worn[-1] > 0.0
    assert depth.sum() * (4e-6) ** 2 == pytest.approx(total, rel=1e-12)
    # The record per simulated cycle and the profiles, as wear.csv and
    # wear_profiles.csv.
    w = res.wear()
    lines = (cli_dir / "wear.csv").read_text().splitlines()
    header = lines[0].split(",")
    assert list(w) == header
    assert len(lines) == 2 and w["cycle"].tolist() == [1]
    for k, name in enumerate(header):
        cli_col = [line.split(",")[k] for line in lines[1:]]
        if name == "regime":
            assert w[name].tolist() == cli_col
        elif name in ("cycle", "worn_through_cells"):
            assert [str(v) for v in w[name]] == cli_col
        else:
            assert np.array(cli_col, dtype=np.float64).tobytes() == w[name].astype(
                np.float64
            ).tobytes(), name
    assert w["worn_volume_m3"][-1] == total
    assert w["depth_max_m"][-1] == depth.max()
    at, saved = res.wear_profiles()
    cli = np.loadtxt(cli_dir / "wear_profiles.csv", delimiter=",", skiprows=1)
    assert list(saved) == [1]
    assert at.tobytes() == cli[:, 0].tobytes()
    assert saved[1][0].tobytes() == cli[:, 1].tobytes()
    assert saved[1][1].tobytes() == cli[:, 2].tobytes()
    # The worn depth at the saved cycle, as the CLI's file (the last: the
    # final field).
    saved_field = res.fields["wear_cycle_1"]
    assert saved_field.tobytes() == np.load(cli_dir / "wear_cycle_1.npy").tobytes()
    assert saved_field.tobytes() == depth.tobytes()
    # The cut along x through the centre of the even grid: the mean of the
    # two middle rows.
    n = depth.shape[0]
    assert np.array_equal(saved[1][0], 0.5 * (depth[n // 2 - 1] + depth[n // 2]))


def test_an_elastic_ball_from_python_equals_the_cli_and_softens_the_contact(
    tmp_path, cli_solve
):
    # indenter.material (issue #35) set from Python and given in the file:
    # the same case, bit for bit; a steel ball on Fe (its own constants)
    # halves the contact modulus, so a grows by 2^(1/3).
    path = tmp_path / "ball.toml"
    path.write_text(
        mindlin_text(ratio=0.6).replace(
            "radius_mm = 18.0", 'radius_mm = 18.0\nmaterial = "steel"'
        )
    )
    case_json, cli_dir = cli_solve(path)
    cfg = mpcontact.Config.from_toml(path)
    res = mpcontact.solve(cfg)
    assert_same_as_cli(res, case_json, cli_dir)
    assert res.scalars["indenter"] == "steel"
    rigid = mpcontact.solve(_rigid(tmp_path))
    ratio = res.scalars["hertz_radius_m"] / rigid.scalars["hertz_radius_m"]
    assert ratio == pytest.approx(2 ** (1 / 3), rel=1e-12)
    assert rigid.scalars["indenter"] == "rigid"


def _rigid(tmp_path):
    path = tmp_path / "rigid.toml"
    path.write_text(mindlin_text(ratio=0.6))
    return mpcontact.Config.from_toml(path)


def test_a_ball_of_the_sweep_axis_solves_from_python_as_from_the_cli(tmp_path, cli_solve):
    # sweep.indenters (issue #35): `indenter=` picks a ball like the CLI's
    # --indenter, the default is the axis's first, and a ball chosen so is
    # the case of a config with indenter.material set to it, to the bit.
    path = tmp_path / "balls.toml"
    path.write_text(
        mindlin_text(ratio=0.6).replace(
            'surfaces = ["flat"]', 'surfaces = ["flat"]\nindenters = ["rigid", "steel"]'
        )
    )
    cfg = mpcontact.Config.from_toml(path)
    assert cfg.indenters == ["rigid", "steel"]
    assert cfg.cases() == [("Fe", "flat", 0.0, "rigid"), ("Fe", "flat", 0.0, "steel")]
    case_json, cli_dir = cli_solve(path, "--indenter", "steel")
    res = mpcontact.solve(cfg, indenter="steel")
    assert_same_as_cli(res, case_json, cli_dir)
    assert res.scalars["indenter"] == "steel"
    one = tmp_path / "steel.toml"
    one.write_text(
        mindlin_text(ratio=0.6).replace(
            "radius_mm = 18.0", 'radius_mm = 18.0\nmaterial = "steel"'
        )
    )
    alone = mpcontact.solve(mpcontact.Config.from_toml(one))
    assert without_times(alone.scalars) == without_times(res.scalars)
    first = mpcontact.solve(cfg)
    assert first.scalars["indenter"] == "rigid"
    assert without_times(first.scalars) == without_times(
        mpcontact.solve(_rigid(tmp_path)).scalars
    )
    with pytest.raises(ValueError, match="indenter: unknown material `unobtainium`"):
        mpcontact.solve(cfg, indenter="unobtainium")


def test_stress_below_the_surface_equals_the_cli_bit_for_bit(tmp_path, cli_solve):
    # Issue #38: with [stress], Result.stress holds the CLI's stress/*.npy
    # arrays and scalars["stress"] its case.json entry; without, None.
    path = tmp_path / "stress.toml"
    path.write_text(
        mindlin_text(ratio=0.6)
        + "\n[stress]\ndepths_um = [0.0, 20.0]\nslice_rows = 6\n"
    )
    case_json, cli_dir = cli_solve(path)
    res = mpcontact.solve(mpcontact.Config.from_toml(path))
    assert without_times(res.scalars) == without_times(case_json)
    names = {p.stem for p in (cli_dir / "stress").glob("*.npy")}
    assert names == set(res.stress), names ^ set(res.stress)
    for name in names:
        theirs = np.load(cli_dir / "stress" / f"{name}.npy")
        assert res.stress[name].tobytes() == theirs.tobytes(), name
    # σzz = −p on the surface plane, cell by cell.
    assert np.array_equal(res.stress["plane_0um_szz"], -res.fields["p"])
    plain = tmp_path / "plain.toml"
    plain.write_text(mindlin_text(ratio=0.6))
    assert mpcontact.solve(mpcontact.Config.from_toml(plain)).stress is None


def test_a_pattern_finer_than_the_grid_is_solved_with_the_clis_warning(tmp_path):
    # Issue #47: a circle lattice whose pitch is 3e-7 of a cell; its cover
    # costs a few islands a cell, and Python warns as the CLI prints.
    configs = REPO / "tests" / "configs"
    text = (configs / "table1c-coarse.toml").read_text()
    text += (configs / "fine-circles.toml").read_text() + """
[sweep]
materials = ["Cu"]
surfaces = ["fine"]
angles_deg = [0.0]
"""
    path = tmp_path / "fine.toml"
    path.write_text(text)
    cfg = mpcontact.Config.from_toml(path)
    (warning,) = cfg.unresolved_patterns()
    assert "surface `fine`" in warning and "below 2 cells per pitch" in warning
    assert cfg.unresolved_patterns(["flat"]) == []
    with pytest.warns(UserWarning, match="below 2 cells per pitch"):
        r = mpcontact.solve(cfg)
    assert r.scalars["converged"]


def test_a_hardness_caps_the_pressure_and_returns_the_dent_as_the_cli(tmp_path, cli_solve):
    # Table 1(a) Fe with H = 0.7 GPa, below Hertz's peak (0.86 GPa): the
    # centre yields; Python and the CLI give the same bits, the dent too.
    hardness_gpa = 0.7
    path = tmp_path / "plastic.toml"
    path.write_text(mindlin_text() + f"\n[materials.Fe]\nhardness_gpa = {hardness_gpa}\n")
    case_json, cli_dir = cli_solve(path)
    res = mpcontact.solve(mpcontact.Config.from_toml(path))
    assert_same_as_cli(res, case_json, cli_dir)
    dent = res.fields["plastic"]
    assert dent.tobytes() == np.load(cli_dir / "plastic.npy").tobytes()
    plastic = res.scalars["plastic"]
    assert plastic["hardness_pa"] == hardness_gpa * 1e9
    assert plastic["plastic_area_m2"] > 0.0
    assert dent.max() == plastic["penetration_max_m"] > 0.0
    assert res.fields["p"].max() <= hardness_gpa * 1e9


def test_an_elastic_pressure_beyond_the_presets_hardness_warns_as_the_cli(tmp_path):
    # Issue #59: circle-B's island edges on Table 1(c) Cu press far beyond
    # copper's 0.4-1.2 GPa; Python warns as `mpcontact solve` does, naming
    # the key that caps the pressure.
    text = """
[grid]
points = 64
spacing_um = 100.0

[indenter]
radius_mm = 200.0

[load]
normal_n = 6000.0
friction = 0.3
tangential_ratio = 0.3

[sweep]
materials = ["Cu"]
surfaces = ["circle-B"]
angles_deg = [0.0]

[solver]
coupling = false
"""
    path = tmp_path / "islands.toml"
    path.write_text(text)
    with pytest.warns(UserWarning, match=r"\[materials.Cu\] hardness_gpa"):
        r = mpcontact.solve(mpcontact.Config.from_toml(path))
    assert r.scalars["p_max_pa"] > 1.2e9
    assert r.scalars["mu_a_contact_radius_m"] > 0.0
    assert r.scalars["mu_a_non_hertz"] in (True, False)
