"""Measured scans (issue #61): the CLI's .x3p reader against
SurfaceTopography's on files these tests write (square and non-square
pixels, missing points, f64 and f32 heights) — heights and sizes to the
bit; topography objects and other formats as surfaces of a case; the
message when SurfaceTopography is missing. Nothing is installed here:
tests/all.sh installs surfacetopography into its venv, and the tests that
need it are skipped, saying why, when the import fails."""

import sys

import numpy as np
import pytest

import mpcontact

try:
    from SurfaceTopography import read_topography

    HAVE_ST = True
    WHY = ""
except ImportError as e:  # pragma: no cover - depends on the venv
    HAVE_ST = False
    WHY = f"surfacetopography cannot be imported ({e}); tests/all.sh installs it"

needs_st = pytest.mark.skipif(not HAVE_ST, reason=WHY)

# (nx, ny, dx, dy, precision, missing points)
FILES = [
    ("square-f64", 64, 64, 0.5e-6, 0.5e-6, "D", 0),
    ("nonsquare-f64", 50, 37, 0.31e-6, 1.7e-6, "D", 0),
    ("nonsquare-f32", 41, 64, 2.5e-6, 0.8e-6, "F", 0),
    ("missing-f64", 48, 40, 1e-6, 1.25e-6, "D", 23),
    ("missing-f32", 33, 47, 0.7e-6, 0.7e-6, "F", 9),
]


def write_scan(tmp_path, name, nx, ny, dx, dy, precision, missing):
    rng = np.random.default_rng(61)
    h = rng.normal(0.0, 1e-6, size=(ny, nx))
    if missing:
        h.flat[rng.choice(nx * ny, size=missing, replace=False)] = np.nan
    path = tmp_path / f"{name}.x3p"
    mpcontact._native.write_x3p(str(path), h, dx, dy, precision)
    return path, h


@needs_st
@pytest.mark.parametrize("name,nx,ny,dx,dy,precision,missing", FILES)
def test_x3p_reading_equals_surfacetopography_to_the_bit(
    tmp_path, name, nx, ny, dx, dy, precision, missing
):
    path, written = write_scan(tmp_path, name, nx, ny, dx, dy, precision, missing)
    ours, odx, ody = mpcontact.read_scan(path)
    topo = read_topography(str(path))
    assert topo.unit == "m"
    assert tuple(topo.nb_grid_pts) == (nx, ny)
    theirs = topo.heights()
    mask = np.ma.getmaskarray(theirs).T
    values = np.ma.getdata(theirs).T.astype(np.float64)
    assert ours.shape == (ny, nx)
    # The same missing points, and every other height to the bit.
    assert np.array_equal(np.isnan(ours), mask | np.isnan(values))
    assert int(np.isnan(ours).sum()) == missing
    known = ~np.isnan(ours)
    assert ours[known].tobytes() == values[known].tobytes()
    # f64 heights are what was written; f32 their rounding.
    want = written if precision == "D" else written.astype(np.float32).astype(np.float64)
    assert ours[known].tobytes() == want[known].tobytes()
    # Pixel sizes as the file gives them, and SurfaceTopography's extents
    # (its increment times the points) and pixel sizes to the bit.
    assert (odx, ody) == (dx, dy)
    sx, sy = topo.physical_sizes
    assert np.float64(odx * nx).tobytes() == np.float64(sx).tobytes()
    assert np.float64(ody * ny).tobytes() == np.float64(sy).tobytes()
    px, py = topo.pixel_size
    assert np.float64(px).tobytes() == np.float64(odx).tobytes()
    assert np.float64(py).tobytes() == np.float64(ody).tobytes()
    print(
        f"{name}: {nx} x {ny}, pixel {odx!r} x {ody!r} (SurfaceTopography {px!r} x {py!r})"
    )


@needs_st
def test_a_topography_object_is_a_surface_of_a_case(tmp_path):
    from SurfaceTopography import Topography

    # Table 1(c) loading on circle-B measured at 10 µm pixels (a
    # topography in µm, as an instrument's reader gives it).
    cfg = mpcontact.Config.from_dict(
        {
            "grid": {"points": 64, "spacing_um": 80.0},
            "indenter": {"radius_mm": 200.0},
            "load": {"normal_n": 6000.0, "friction": 0.3, "tangential_ratio": 0.6},
            "sweep": {"materials": ["Cu"], "surfaces": ["flat"], "angles_deg": [0.0]},
        }
    )
    n, pixel = 512, 10.0
    x = (np.arange(n) - (n - 1) / 2) * pixel
    xx, yy = np.meshgrid(x, x, indexing="ij")
    u = xx - 640.0 * np.round(xx / 640.0)
    v = yy - 640.0 * np.round(yy / 640.0)
    heights = np.where(np.hypot(u, v) <= 200.0, 30.0, 0.0)
    topo = Topography(heights, (n * pixel, n * pixel), unit="µm")
    res = mpcontact.solve(cfg, surface=topo)
    scan = res.scalars["surface_scan"]
    assert scan["pixels"] == [n, n]
    assert scan["pixel_um"] == pytest.approx([pixel, pixel], rel=1e-12)
    assert scan["levelling"] == "plane"
    # Two levels 30 µm apart.
    assert scan["scan"]["sz_um"] == pytest.approx(30.0, rel=1e-9)
    # The same scan converted to .x3p and named in a config is the same case.
    out = mpcontact.convert(topo, tmp_path / "b.x3p")
    named = mpcontact.with_scan(cfg, "b", out)
    again = mpcontact.solve(named, surface="b")
    assert again.scalars["mu_a"] == res.scalars["mu_a"]
    assert "b" in named.surfaces


def test_missing_surfacetopography_is_a_clear_message(monkeypatch, tmp_path):
    monkeypatch.setitem(sys.modules, "SurfaceTopography", None)
    monkeypatch.setitem(sys.modules, "SurfaceTopography.Support.UnitConversion", None)
    source = tmp_path / "scan.plu"
    source.write_bytes(b"not read")
    with pytest.raises(ImportError) as e:
        mpcontact.convert(source, tmp_path / "scan.x3p")
    text = str(e.value)
    assert "surfacetopography is not installed" in text
    assert "pip install 'mpcontact[surfacetopography]'" in text
    # .x3p and .npy need nothing more.
    path, _ = write_scan(tmp_path, "plain", 8, 8, 1e-6, 1e-6, "D", 0)
    h, dx, dy = mpcontact.read_scan(path)
    assert h.shape == (8, 8)


def test_bad_scan_files_name_the_file(tmp_path):
    cut = tmp_path / "cut.x3p"
    path, _ = write_scan(tmp_path, "whole", 40, 40, 1e-6, 1e-6, "D", 0)
    cut.write_bytes(path.read_bytes()[:-200])
    with pytest.raises(ValueError, match=r"cut\.x3p.*(corrupt|truncated)"):
        mpcontact.read_scan(cut)
    with pytest.raises(ValueError, match=r"unknown scan format `\.sur`.*\.x3p"):
        mpcontact.read_scan(tmp_path / "scan.sur")
