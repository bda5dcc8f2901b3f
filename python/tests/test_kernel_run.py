"""kernel() and materials() against the CLI; run() with two workers."""

import json
import subprocess

import numpy as np
import pytest

import mpcontact


def test_materials_are_the_cli_presets(cli):
    table = subprocess.run([str(cli), "materials"], capture_output=True, text=True, check=True)
    lines = table.stdout.splitlines()[1:]
    names = [l.split()[0] for l in lines[: lines.index("")]]
    assert mpcontact.materials() == names
    assert {"Fe", "Cu", "Cu(111)"} <= set(names)


@pytest.mark.parametrize("material", ["Fe", "Cu(111)"])
def test_kernel_equals_the_cli_kernel_bit_for_bit(cli, material):
    out = subprocess.run(
        [str(cli), "kernel", "--material", material, "--angles-deg", "0:180:45"],
        capture_output=True,
        text=True,
        check=True,
    )
    rows = json.loads(out.stdout)
    h = mpcontact.kernel(material, [0, 45, 90, 135, 180])
    assert h.shape == (5, 3, 3) and h.dtype == np.complex128
    # Parts set one by one: re + 1j*im would turn −0.0 parts into +0.0.
    theirs = np.empty((len(rows), 3, 3), dtype=np.complex128)
    theirs.real = [r["H_re"] for r in rows]
    theirs.imag = [r["H_im"] for r in rows]
    assert h.tobytes() == theirs.tobytes()


def test_isotropic_kernel_is_the_closed_form():
    """Isotropic half-space: H_zz = 2(1 − ν²)/E at every angle (1/Pa, per |k|)."""
    cfg = mpcontact.Config.from_dict(
        {
            "grid": {"points": 64, "spacing_um": 6.0},
            "indenter": {"radius_mm": 18.0},
            "load": {"normal_n": 20.0, "friction": 0.3},
            "sweep": {"materials": ["soft"]},
            "materials": {"soft": {"isotropic": {"youngs_gpa": 100.0, "poisson": 0.25}}},
        }
    )
    h = mpcontact.kernel("soft", np.linspace(0, 180, 7), cfg=cfg)
    assert np.allclose(h[:, 2, 2].real, 2 * (1 - 0.25**2) / 100e9, rtol=1e-9)
    with pytest.raises(ValueError, match="unknown preset"):
        mpcontact.kernel("soft", [0.0])
    with pytest.raises(ValueError, match="finite"):
        mpcontact.kernel("Fe", [np.nan])


def test_a_sweep_on_two_workers_returns_every_case_equal_to_solve(tmp_path):
    cfg = mpcontact.Config.from_dict(
        {
            "grid": {"points": 64, "spacing_um": 6.0},
            "indenter": {"radius_mm": 18.0},
            "load": {"normal_n": 20.0, "friction": 0.28571, "tangential_ratio": 0.6},
            "sweep": {"materials": ["Fe", "Cu"], "surfaces": ["flat"], "angles_deg": [0, 45, 90]},
            "solver": {"coupling": False, "tolerance": 1e-10, "tangential_tolerance": 1e-6},
        }
    )
    out = tmp_path / "sweep"
    res = mpcontact.run(cfg, workers=2, out=out, progress=False)
    r = res.results
    assert len(r["material"]) == 6
    assert sorted(zip(r["material"], r["angle_deg"])) == sorted(
        (m, a) for m in ("Fe", "Cu") for a in (0.0, 45.0, 90.0)
    )
    assert list(r["status"]) == ["ok"] * 6
    assert set(r["worker"]) <= {0.0, 1.0, 2.0, 3.0}
    assert res.summary["total"] == 6 and res.summary["ok"] == 6
    assert len(res.curves["mu_a"]) == 6
    for name in ("results.csv", "curves.csv", "summary.json", "journal.jsonl"):
        assert (out / name).is_file(), name
    # Each row is the in-process solve of the same case, to the bit.
    for m, a, mu, c in zip(r["material"], r["angle_deg"], r["mu_a"], r["stick_radius_m"]):
        s = mpcontact.solve(cfg, material=str(m), angle_deg=a).scalars
        assert (mu, c) == (s["mu_a"], s["stick_radius_m"])


def test_run_resumes_and_defaults_to_a_temporary_directory(tmp_path):
    cfg = mpcontact.Config.from_dict(
        {
            "grid": {"points": 64, "spacing_um": 6.0},
            "indenter": {"radius_mm": 18.0},
            "load": {"normal_n": 20.0, "friction": 0.3},
            "sweep": {"materials": ["Fe"], "angles_deg": [0]},
        }
    )
    first = mpcontact.run(cfg, workers=1, progress=False)
    assert first.out.is_dir() and list(first.results["status"]) == ["ok"]
    again = mpcontact.run(cfg, workers=1, out=first.out, resume=True, progress=False)
    assert again.summary["resumed"] == 1
    # Without resume=True the folder is refused, in Python's words (#62).
    with pytest.raises(RuntimeError) as refused:
        mpcontact.run(cfg, workers=1, out=first.out, progress=False)
    text = str(refused.value)
    assert "already holds a sweep" in text and "resume=True" in text and "out=" in text, text
    assert "--resume" not in text and "--out" not in text, text
    with pytest.raises(ValueError, match="workers"):
        mpcontact.run(cfg, workers=0, out=tmp_path / "none", progress=False)
    (tmp_path / "file").write_text("")
    with pytest.raises(RuntimeError, match="^out= .*file: exists and is not a directory"):
        mpcontact.run(cfg, workers=1, out=tmp_path / "file", progress=False)


def test_a_sweep_over_balls_returns_a_row_per_ball(tmp_path):
    # sweep.indenters (issue #35): one run compares balls; each row is the
    # in-process solve of its case with its ball, to the bit.
    cfg = mpcontact.Config.from_dict(
        {
            "grid": {"points": 64, "spacing_um": 6.0},
            "indenter": {"radius_mm": 18.0},
            "load": {"normal_n": 20.0, "friction": 0.28571, "tangential_ratio": 0.6},
            "sweep": {
                "materials": ["Fe"],
                "angles_deg": [0, 90],
                "indenters": ["rigid", "steel"],
            },
            "solver": {"coupling": False, "tolerance": 1e-10, "tangential_tolerance": 1e-6},
        }
    )
    res = mpcontact.run(cfg, workers=2, out=tmp_path / "balls", progress=False)
    r = res.results
    assert sorted(zip(r["indenter"], r["angle_deg"])) == [
        ("rigid", 0.0),
        ("rigid", 90.0),
        ("steel", 0.0),
        ("steel", 90.0),
    ]
    assert list(res.curves["indenter"]) == list(r["indenter"])
    for b, a, mu in zip(r["indenter"], r["angle_deg"], r["mu_a"]):
        s = mpcontact.solve(cfg, angle_deg=a, indenter=str(b)).scalars
        assert mu == s["mu_a"]


def test_a_fretting_map_returns_its_table(tmp_path):
    # sweep.amplitudes_um (issue #37): run() reads fretting_map.csv and
    # fretting_transitions.csv as the CLI writes them.
    cfg = mpcontact.Config.from_dict(
        {
            "grid": {"points": 64, "spacing_um": 120.0},
            "indenter": {"radius_mm": 200.0},
            "load": {"normal_n": 6000.0, "friction": 0.3},
            "sweep": {"materials": ["Cu"], "angles_deg": [0], "amplitudes_um": [3.0, 12.0]},
            "solver": {"coupling": False},
            "history": {"fretting": {"cycles": 1}, "steps_per_segment": 5},
        }
    )
    res = mpcontact.run(cfg, workers=2, out=tmp_path / "map", progress=False)
    m = res.fretting_map
    assert list(m["amplitude_um"]) == [3.0, 12.0]
    assert list(m["regime"]) == ["partial", "gross"]
    t = res.fretting_transitions["transition_um"]
    assert 3.0 < t[0] < 12.0
    assert (res.out / "fretting_map.png").exists()


def test_an_orientation_sweep_returns_its_table(tmp_path):
    # sweep.orientations (issue #39): run() reads orientations.csv, and a
    # crystal cut at an orientation solves by its name as a single case.
    cfg = mpcontact.Config.from_dict(
        {
            "grid": {"points": 32, "spacing_um": 200.0},
            "indenter": {"radius_mm": 200.0},
            "load": {"normal_n": 6000.0, "friction": 0.3, "tangential_ratio": 0.6},
            "sweep": {
                "materials": ["Cu"],
                "angles_deg": [0, 90],
                "orientations": [[0, 0, 1], [1, 1, 1]],
            },
            "materials": {"Cu": {"cubic_gpa": {"c11": 168.4, "c12": 121.4, "c44": 75.4}}},
        }
    )
    res = mpcontact.run(cfg, workers=2, out=tmp_path / "orient", progress=False)
    t = res.orientations
    assert list(t["orientation"]) == ["[0 0 1]", "[1 1 1]"]
    m = t["indentation_modulus_gpa"]
    assert 1.12 < m[1] / m[0] < 1.14
    assert (res.out / "ipf" / "Cu" / "indentation_modulus.png").exists()
    r = res.results
    for name, a, dz in zip(r["material"], r["angle_deg"], r["delta_z_m"]):
        s = mpcontact.solve(cfg, material=str(name), angle_deg=a).scalars
        assert s["delta_z_m"] == dz
    assert set(r["material"]) == {"Cu[0 0 1]", "Cu[1 1 1]"}
