#!/usr/bin/env python3
"""The .x3p reader against SurfaceTopography on the sample scans of
SurfaceTopography's own test suite (issue #61).

    scan_samples.py DIR

DIR holds sample files of `test/file_format_examples` of
ContactEngineering/SurfaceTopography (not part of this repository; several
are stored there as large files, absent from a plain clone). For every
`.x3p` in DIR: mpcontact's reading (`mpcontact.read_scan`, the CLI's
reader) and SurfaceTopography's (`read_topography`) — points, pixel sizes,
extents, missing points and every height, compared bit for bit. For every
other file SurfaceTopography reads: `mpcontact.convert` to `.x3p` and back
through the CLI's reader, against SurfaceTopography's heights in metres
(bit for bit where the conversion to metres is exact, else the largest
relative difference). Needs the mpcontact package and surfacetopography in
the running Python. Prints a markdown table.
"""

import os
import sys
import tempfile

import numpy as np

import mpcontact
from SurfaceTopography import read_topography
from SurfaceTopography.Support.UnitConversion import get_unit_conversion_factor


def st_heights(topo):
    """SurfaceTopography's heights in its unit, (ny, nx), NaN where masked."""
    h = topo.heights()
    mask = np.ma.getmaskarray(h)
    return np.where(mask, np.nan, np.ma.getdata(h).astype(np.float64)).T


def same_bits(a, b):
    known = ~np.isnan(a)
    return bool(np.array_equal(np.isnan(a), np.isnan(b))) and a[known].tobytes() == b[known].tobytes()


def main():
    folder = sys.argv[1]
    rows = []
    for name in sorted(os.listdir(folder)):
        path = os.path.join(folder, name)
        if os.path.getsize(path) == 0:
            continue
        try:
            topo = read_topography(path)
        except Exception as e:  # noqa: BLE001 - a format it does not read
            print(f"{name}: SurfaceTopography cannot read it ({type(e).__name__})", file=sys.stderr)
            continue
        if topo.dim != 2:
            continue
        theirs = st_heights(topo)
        nx, ny = topo.nb_grid_pts
        if name.lower().endswith(".x3p"):
            ours, dx, dy = mpcontact.read_scan(path)
            route = "read"
            f = 1.0
        else:
            with tempfile.TemporaryDirectory() as d:
                out = mpcontact.convert(path, os.path.join(d, "s.x3p"))
                ours, dx, dy = mpcontact.read_scan(out)
            route = "convert + read"
            f = get_unit_conversion_factor(topo.unit, "m")
        want = theirs * f
        sx, sy = (v * f for v in topo.physical_sizes)
        bits = same_bits(ours, want)
        known = ~np.isnan(want)
        rel = float(np.max(np.abs(ours[known] - want[known])) / np.max(np.abs(want[known])))
        rows.append(
            (
                name,
                route,
                f"{nx} x {ny}",
                f"{dx * 1e6:.6g} x {dy * 1e6:.6g}",
                "yes" if (dx * nx, dy * ny) == (sx, sy) else f"{dx * nx!r} vs {sx!r}",
                int(np.isnan(want).sum()),
                int(np.isnan(ours).sum()),
                "yes" if bits else f"no (largest {rel:.1e})",
            )
        )
    print("| file | route | points | pixel (µm) | extent to the bit | missing (ST) | missing (ours) | heights to the bit |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print("| " + " | ".join(str(v) for v in r) + " |")


if __name__ == "__main__":
    main()
