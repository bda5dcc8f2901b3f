"""``python -m mpcontact.convert FILE OUT.x3p``: any scan SurfaceTopography
reads, written as an ISO 25178-72 ``.x3p`` that ``mpcontact run`` reads
(``[surfaces.NAME] shape = "scan"``, ``file = "OUT.x3p"``)."""

import sys

import numpy as np

from mpcontact.scans import convert, read_scan


def main(argv=None):
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 2 or not args[1].lower().endswith(".x3p"):
        print("usage: python -m mpcontact.convert FILE OUT.x3p", file=sys.stderr)
        return 2
    try:
        out = convert(args[0], args[1])
    except (ImportError, ValueError, FileNotFoundError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    h, dx, dy = read_scan(out)
    ny, nx = h.shape
    print(
        f"{out}: {nx} x {ny} pixels of {dx * 1e6:.6g} x {dy * 1e6:.6g} µm, "
        f"{int(np.isnan(h).sum())} missing"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
