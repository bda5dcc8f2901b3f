"""Shared fixtures: the CLI binary to compare against, small configs, and a
kernel cache private to the test session."""

import json
import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]

# Hertz / Cattaneo–Mindlin on isotropic Fe (paper Table 1(a), the fragment
# tests/configs/table1a-fe.toml that the CLI tests share) at 96², 4 µm
# cells: a ≈ 105 µm spans ~26 cells and the contact stays well inside the
# 384 µm domain.
TABLE_1A_FE = (REPO / "tests" / "configs" / "table1a-fe.toml").read_text()

MINDLIN_SOLVER = """
[solver]
coupling = {coupling}
tolerance = 1e-10
tangential_tolerance = 1e-6
max_iterations = 5000
"""


def mindlin_text(ratio=0.6, angle=0.0, coupling="false"):
    text = TABLE_1A_FE
    for old, new in (
        ("tangential_ratio = 0.6", f"tangential_ratio = {ratio}"),
        ("angles_deg = [30.0]", f"angles_deg = [{angle}]"),
    ):
        assert old in text, f"tests/configs/table1a-fe.toml has no '{old}'"
        text = text.replace(old, new)
    grid = "[grid]\npoints = 96\nspacing_um = 4.0\n\n"
    return grid + text + MINDLIN_SOLVER.format(coupling=coupling)


# Paper Table 1(c) loading (R = 200 mm, P = 6 kN, μ = 0.3, F = 0.6 μP) on a
# coarse 64² grid of 120 µm cells: the patterned and height-map cases.
PATTERN = """
[grid]
points = 64
spacing_um = 120.0
[indenter]
radius_mm = 200.0
[load]
normal_n = 6000.0
friction = 0.3
tangential_ratio = 0.6
[sweep]
materials = ["{material}"]
surfaces = ["{surface}"]
angles_deg = [{angle}]
"""


def pattern_text(material, surface, angle, extra=""):
    return PATTERN.format(material=material, surface=surface, angle=angle) + extra


@pytest.fixture(scope="session", autouse=True)
def private_kernel_cache(tmp_path_factory):
    """Anisotropic kernels go to a directory of this session, for the
    Python solves and the CLI alike (both read MPCONTACT_CACHE_DIR)."""
    d = tmp_path_factory.mktemp("kernels")
    old = os.environ.get("MPCONTACT_CACHE_DIR")
    os.environ["MPCONTACT_CACHE_DIR"] = str(d)
    yield d
    if old is None:
        os.environ.pop("MPCONTACT_CACHE_DIR", None)
    else:
        os.environ["MPCONTACT_CACHE_DIR"] = old


@pytest.fixture(scope="session")
def cli():
    """The `mpcontact` binary of this checkout (tests/all.sh builds it)."""
    candidates = []
    if os.environ.get("MPCONTACT_CLI"):
        candidates.append(Path(os.environ["MPCONTACT_CLI"]))
    target = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    candidates.append(target / "release" / "mpcontact")
    for c in candidates:
        if c.is_file() and os.access(c, os.X_OK):
            return c
    pytest.fail(
        "no mpcontact binary: build it with `cargo build --release` "
        f"or set MPCONTACT_CLI (looked at {', '.join(map(str, candidates))})"
    )


@pytest.fixture
def cli_solve(cli, tmp_path):
    """Runs `mpcontact solve CONFIG --out DIR [args]`; returns (case.json dict, DIR)."""

    def run(config_path, *args):
        out = tmp_path / f"cli-{len(list(tmp_path.iterdir()))}"
        subprocess.run(
            [str(cli), "solve", str(config_path), "--out", str(out), *args],
            check=True,
            capture_output=True,
            text=True,
        )
        return json.loads((out / "case.json").read_text()), out

    return run
