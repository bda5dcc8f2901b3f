"""Measured and random surfaces from Python.

Any file SurfaceTopography reads (more than 40 instrument formats) and any
SurfaceTopography topography object becomes a surface of a case or a
sweep: it is written as an ISO 25178-72 ``.x3p`` — the format the CLI
reads natively — and named in the config as ``shape = "scan"``, so
levelling, missing points and resampling are the CLI's own::

    cfg = mpcontact.with_scan(cfg, "ground", "ground.plu", levelling="plane")
    res = mpcontact.solve(cfg, surface="ground")
    mpcontact.convert("ground.plu", "ground.x3p")   # for mpcontact run

``.x3p`` and ``.npy`` files need nothing more; other formats and
topography objects need the optional extra ``surfacetopography``
(``pip install 'mpcontact[surfacetopography]'``).
"""

import atexit
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np

from mpcontact import _native

#: The message when SurfaceTopography is needed but not installed.
MISSING_SURFACETOPOGRAPHY = (
    "surfacetopography is not installed: reading {what} needs it "
    "(mpcontact itself reads .x3p and .npy). Install it with "
    "pip install 'mpcontact[surfacetopography]' (or pip install surfacetopography)"
)


def _surfacetopography(what):
    try:
        import SurfaceTopography
        from SurfaceTopography.Support.UnitConversion import (
            get_unit_conversion_factor,
        )
    except ImportError as e:
        raise ImportError(MISSING_SURFACETOPOGRAPHY.format(what=what)) from e
    return SurfaceTopography, get_unit_conversion_factor


def read_scan(path, pixel_um=None):
    """The CLI's reading of a scan file: ``(heights, dx, dy)`` — heights in
    m, shape ``(ny, nx)`` (rows along y), NaN where a point is missing;
    pixel sizes in m. ``.x3p`` as the file says; ``.npy`` (heights in µm)
    with ``pixel_um = (dx, dy)``."""
    pixel = None if pixel_um is None else tuple(float(v) for v in pixel_um)
    if pixel is not None and len(pixel) == 1:
        pixel = (pixel[0], pixel[0])
    return _native.read_scan(os.fspath(path), pixel)


def topography_heights(topography):
    """A SurfaceTopography topography as ``(heights, dx, dy)``: heights in
    m, ``(ny, nx)``, rows along y, NaN where a point is missing (masked);
    pixel sizes in m, from its unit."""
    _, factor_of = _surfacetopography("a topography object")
    if getattr(topography, "dim", 2) != 2:
        raise ValueError(
            "a 1-D profile (a line scan): contact needs a 2-D map of heights"
        )
    unit = topography.unit
    if unit is None:
        raise ValueError(
            "the topography has no unit: give it one (SurfaceTopography: topography.scale / unit=)"
        )
    factor = factor_of(unit, "m")
    h = np.ma.getdata(topography.heights()).astype(np.float64)
    mask = np.ma.getmaskarray(topography.heights())
    h = np.where(mask, np.nan, h)
    dx, dy = topography.pixel_size
    return np.ascontiguousarray(h.T * factor), float(dx) * factor, float(dy) * factor


def convert(source, out, precision="D"):
    """One line from any format SurfaceTopography reads (a path) or any
    topography object to an ``.x3p`` the CLI reads: heights, pixel sizes
    (not necessarily square), units and missing points kept. Returns the
    output path. ``precision``: ``"D"`` (f64) or ``"F"`` (f32)."""
    if hasattr(source, "heights"):
        topography = source
    else:
        path = Path(source)
        if not path.is_file():
            raise FileNotFoundError(f"{path}: no such file")
        st, _ = _surfacetopography(f"{path.suffix or 'this'} files")
        try:
            topography = st.read_topography(str(path))
        except Exception as e:  # SurfaceTopography's readers raise many kinds
            raise ValueError(f"{path}: SurfaceTopography cannot read it: {e}") from e
    h, dx, dy = topography_heights(topography)
    out = Path(out)
    _native.write_x3p(str(out), h, dx, dy, precision)
    return out


_converted = None


def _scratch():
    """A directory for converted scans, removed when Python exits."""
    global _converted
    if _converted is None:
        _converted = tempfile.mkdtemp(prefix="mpcontact-scans-")
        atexit.register(shutil.rmtree, _converted, True)
    return Path(_converted)


def scan_file(source, name="scan"):
    """The file the CLI reads for ``source``: an ``.x3p`` or ``.npy`` path
    as it is; another path or a topography object converted to an
    ``.x3p`` in a scratch directory."""
    if not hasattr(source, "heights"):
        path = Path(source)
        if path.suffix.lower() in (".x3p", ".npy"):
            return path.resolve()
    return convert(source, _scratch() / f"{name}.x3p").resolve()


def with_scan(cfg, name, source, sweep=True, **keys):
    """A copy of ``cfg`` with ``[surfaces.NAME]`` the scan ``source`` (a
    path in any format SurfaceTopography reads, or a topography object),
    ``shape = "scan"``, and the other keys of such a table
    (``levelling``, ``degree``, ``missing``, ``apex_um``, ``pixel_um`` for
    an ``.npy``). With ``sweep``, ``name`` joins ``sweep.surfaces``."""
    out = cfg.copy()
    items = {
        f"surfaces.{name}.shape": "scan",
        f"surfaces.{name}.file": str(scan_file(source, name)),
    }
    for key, value in keys.items():
        items[f"surfaces.{name}.{key}"] = value
    if sweep and name not in out.surfaces:
        items["sweep.surfaces"] = list(out.surfaces) + [name]
    out.set_many(items)
    return out
