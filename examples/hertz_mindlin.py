"""Pressure, shear traction and stick zone of one solve against the closed
forms: Hertz p = p0 sqrt(1 − r²/a²) and Cattaneo–Mindlin
q = μ p0 [sqrt(1 − r²/a²) − (c/a) sqrt(1 − r²/c²)] with the stick radius
c = a (1 − Q/μP)^(1/3), on the uncoupled Fe case of the paper's Table 1(a).

    python examples/hertz_mindlin.py                      # writes hertz_mindlin.png
    python examples/hertz_mindlin.py --points 512 --png out.png

Needs matplotlib (not needed by the package or its tests).
"""

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only, no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import mpcontact  # noqa: E402

REPO = Path(__file__).resolve().parents[1]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--config", type=Path, default=REPO / "configs" / "mindlin-uncoupled.toml")
    ap.add_argument("--points", type=int, default=256, help="grid.points (the domain is kept)")
    ap.add_argument("--png", type=Path, default=Path("hertz_mindlin.png"))
    args = ap.parse_args()

    cfg = mpcontact.Config.from_toml(args.config)
    # Keep the domain size: spacing × points constant.
    domain_um = cfg.spacing_um * cfg.grid_points
    cfg.set("grid.points", args.points)
    cfg.set("grid.spacing_um", domain_um / args.points)
    res = mpcontact.solve(cfg, angle_deg=0.0)
    s, f = res.scalars, res.fields

    load = s["spec"]["load"]
    P, mu, ratio = load["normal_force_n"], load["friction"], load["tangential_ratio"]
    a_h, p0 = s["hertz_radius_m"], s["hertz_pressure_pa"]
    c_m = a_h * (1 - ratio) ** (1 / 3)
    x, y = res.coordinates_m()
    mid = len(y) // 2  # the row nearest y = 0 (x-axis through the apex)

    r = np.linspace(-1.2 * a_h, 1.2 * a_h, 801)
    hertz = p0 * np.sqrt(np.clip(1 - r**2 / a_h**2, 0, None))
    mindlin = mu * hertz - mu * p0 * (c_m / a_h) * np.sqrt(np.clip(1 - r**2 / c_m**2, 0, None))

    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6), constrained_layout=True)
    ax = axes[0]
    ax.plot(r / a_h, hertz / p0, "k-", label="Hertz p0 √(1 − r²/a²)")
    ax.plot(x / a_h, f["p"][mid] / p0, "o", ms=3, label="mpcontact p (y ≈ 0)")
    ax.set_xlabel("x / a_H")
    ax.set_ylabel("p / p_H")
    ax.set_title(f"pressure: a = {s['contact_radius_m'] * 1e6:.1f} µm (Hertz {a_h * 1e6:.1f} µm)")
    ax.legend()

    ax = axes[1]
    ax.plot(r / a_h, mindlin / p0, "k-", label="Cattaneo–Mindlin")
    ax.plot(x / a_h, f["qx"][mid] / p0, "o", ms=3, label="mpcontact qx (y ≈ 0)")
    ax.set_xlabel("x / a_H")
    ax.set_ylabel("q / p_H")
    ax.set_title(f"shear traction, Q/μP = {ratio}")
    ax.legend()

    ax = axes[2]
    ext = np.array([x[0], x[-1], y[0], y[-1]]) / a_h
    ax.imshow(f["stick"] + (f["p"] > 0), origin="lower", extent=ext, cmap="Greys", vmin=0, vmax=2)
    t = np.linspace(0, 2 * np.pi, 400)
    ax.plot(np.cos(t), np.sin(t), "b-", label="Hertz contact a")
    ax.plot(c_m / a_h * np.cos(t), c_m / a_h * np.sin(t), "r--", label=f"Mindlin c = a (1 − Q/μP)^1/3")
    ax.set_xlim(-1.3, 1.3)
    ax.set_ylim(-1.3, 1.3)
    ax.set_xlabel("x / a_H")
    ax.set_ylabel("y / a_H")
    ax.set_title(f"stick zone (dark): c = {s['stick_radius_m'] * 1e6:.1f} µm (Mindlin {c_m * 1e6:.1f} µm)")
    ax.legend(loc="upper right", fontsize="small")
    fig.savefig(args.png, dpi=120)
    print(
        f"a = {s['contact_radius_m']:.4e} m (Hertz {a_h:.4e}), c = {s['stick_radius_m']:.4e} m "
        f"(Mindlin {c_m:.4e}), p_max = {s['p_max_pa']:.4e} Pa (p0 {p0:.4e}) → {args.png}"
    )


if __name__ == "__main__":
    main()
