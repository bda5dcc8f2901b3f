"""mpcontact: frictional contact of a rigid sphere on an elastic half-space.

The Rust solver and sweep runner of the ``mpcontact`` command line, called
from Python — the same config loader, solve, kernels and worker processes,
not a second implementation::

    import mpcontact
    cfg = mpcontact.Config.from_toml("configs/mindlin-uncoupled.toml")
    cfg.set("grid.points", 128)
    res = mpcontact.solve(cfg)
    res.scalars["contact_radius_m"], res.fields["p"].shape

See ``python/README.md`` for the whole API with examples.
"""

import csv
import os
import sys
import tempfile
from pathlib import Path

from mpcontact import _native
from mpcontact._native import Config, SolveError
from mpcontact.scans import convert, read_scan, scan_file, with_scan

__all__ = [
    "Config",
    "Result",
    "RunResult",
    "SolveError",
    "FIELD_NAMES",
    "convert",
    "kernel",
    "materials",
    "read_scan",
    "run",
    "solve",
    "with_scan",
]

#: The fields of a solved case, as the CLI's ``.npy`` files are named.
FIELD_NAMES = ("p", "qx", "qy", "sx", "sy", "stick", "ux", "uy", "uz")


class Result:
    """One solved case.

    ``scalars``: dict with exactly the keys and values of the CLI's
    ``case.json`` (same serde value). ``fields``: dict of float64 ``(n, n)``
    arrays, rows along y, SI units (Pa, m; ``stick`` is 0/1) — the CLI's
    ``.npy`` files. ``stress``: with a ``[stress]`` section, dict of the
    stresses below the surface named as the CLI's ``stress/*.npy`` files
    (``plane_<z>um_<c>``, ``slice_along_<c>``, …; Pa), else ``None``; their
    maxima are in ``scalars["stress"]``.
    """

    __slots__ = ("scalars", "fields", "stress")

    def __init__(self, scalars, fields, stress=None):
        self.scalars = scalars
        self.fields = fields
        self.stress = stress

    @property
    def spacing_m(self):
        """Cell size, m."""
        return self.scalars["spacing_m"]

    def coordinates_m(self):
        """``(x, y)`` cell-centre coordinates, m, as 1-D arrays (the grid is
        centred on the sphere's apex)."""
        import numpy as np

        n = self.scalars["grid_points"]
        c = (np.arange(n) - (n - 1) / 2.0) * self.spacing_m
        return c, c.copy()

    def history(self):
        """The load path's table of a case with ``[history]`` (fretting,
        proportional loading), else ``None``: a dict of 1-D arrays named as
        the columns of the CLI's ``history.csv`` (``step``,
        ``normal_force_n``, ``fx_n``, ``fy_n``, ``delta_x_m``, ``delta_y_m``,
        ``delta_z_m``, ``contact_area_m2``, ``stick_area_m2``,
        ``stick_radius_m`` (the stick zone's own radius, its outline),
        ``dissipated_j``, ``segment``, ``converged``,
        ``segment_increments`` (the increments the row's segment took), and
        ``worn_volume_m3`` with a wear law, ``plastic_area_m2`` and
        ``plastic_penetration_max_m`` on a surface with a hardness). The per-cycle energy, reversal stiffness and residual shift are in
        ``scalars`` as in ``case.json``."""
        h = self.scalars.get("history")
        if h is None:
            return None
        import numpy as np

        def col(get, dtype=np.float64):
            return _table_column(h["steps"], get, dtype)

        table = {
            "step": col(lambda r: r["step"], np.int64),
            "normal_force_n": col(lambda r: r["normal_force_n"]),
            "fx_n": col(lambda r: r["force_n"][0]),
            "fy_n": col(lambda r: r["force_n"][1]),
            "delta_x_m": col(lambda r: r["delta_t_m"][0]),
            "delta_y_m": col(lambda r: r["delta_t_m"][1]),
            "delta_z_m": col(lambda r: r["delta_z_m"]),
            "contact_area_m2": col(lambda r: r["contact_area_m2"]),
            "stick_area_m2": col(lambda r: r["stick_area_m2"]),
            "stick_radius_m": col(lambda r: r["stick_radius_m"]),
            "dissipated_j": col(lambda r: r["dissipated_j"]),
            "segment": col(lambda r: r["segment"], np.int64),
            "converged": col(lambda r: r["converged"], bool),
            "segment_increments": col(lambda r: r.get("segment_increments", 0), np.int64),
        }
        # With a wear law, as the CLI's history.csv: the volume worn so far.
        if h.get("worn_volume_m3") is not None:
            table["worn_volume_m3"] = col(lambda r: r["worn_volume_m3"])
        # With a hardness, as the CLI's history.csv: the area at the cap and
        # the dent's deepest cell so far.
        if any(r.get("plastic_area_m2") is not None for r in h["steps"]):
            table["plastic_area_m2"] = col(lambda r: r.get("plastic_area_m2") or 0.0)
            table["plastic_penetration_max_m"] = col(
                lambda r: r.get("plastic_penetration_max_m") or 0.0
            )
        return table

    def wear(self):
        """The wear record of a path with ``history.wear``, else ``None``: a
        dict of 1-D arrays, one entry per simulated cycle, named as the
        columns of the CLI's ``wear.csv`` (``cycle``, ``physical_cycles``,
        ``worn_volume_m3``, ``worn_volume_per_cycle_m3``, ``depth_max_m``,
        ``depth_max_x_m``, ``depth_max_y_m``, ``depth_increment_max_m``,
        ``scar_area_m2``, ``scar_extent_x_m``, ``scar_extent_y_m``,
        ``contact_radius_m``, ``stick_radius_m`` (the zones' own radii),
        ``force_amplitude_n``,
        ``shift_amplitude_m``, ``dissipated_j``, ``regime``,
        ``worn_through_cells``, ``ball_worn_volume_m3``, ``ball_depth_max_m``)."""
        h = self.scalars.get("history")
        if h is None or not h.get("wear_cycles"):
            return None
        import numpy as np

        def col(get, dtype=np.float64):
            return _table_column(h["wear_cycles"], get, dtype)

        return {
            "cycle": col(lambda c: c["cycle"], np.int64),
            "physical_cycles": col(lambda c: c["physical_cycles"]),
            "worn_volume_m3": col(lambda c: c["worn_volume_m3"]),
            "worn_volume_per_cycle_m3": col(lambda c: c["worn_volume_per_cycle_m3"]),
            "depth_max_m": col(lambda c: c["depth_max_m"]),
            "depth_max_x_m": col(lambda c: c["depth_max_at_m"][0]),
            "depth_max_y_m": col(lambda c: c["depth_max_at_m"][1]),
            "depth_increment_max_m": col(lambda c: c["depth_increment_max_m"]),
            "scar_area_m2": col(lambda c: c["scar_area_m2"]),
            "scar_extent_x_m": col(lambda c: c["scar_extent_m"][0]),
            "scar_extent_y_m": col(lambda c: c["scar_extent_m"][1]),
            "contact_radius_m": col(lambda c: c["contact_radius_m"]),
            "stick_radius_m": col(lambda c: c["stick_radius_m"]),
            "force_amplitude_n": col(lambda c: c["force_amplitude_n"]),
            "shift_amplitude_m": col(lambda c: c["shift_amplitude_m"]),
            "dissipated_j": col(lambda c: c["dissipated_j"]),
            "regime": col(lambda c: c["regime"], object),
            "worn_through_cells": col(lambda c: c["worn_through_cells"], np.int64),
            "ball_worn_volume_m3": col(lambda c: c["ball_worn_volume_m3"]),
            "ball_depth_max_m": col(lambda c: c["ball_depth_max_m"]),
        }

    def wear_profiles(self):
        """The worn profiles through the contact's centre at the saved
        cycles (``history.save_every`` and the last), as the CLI's
        ``wear_profiles.csv``: ``(position_m, {cycle: (along_x, along_y)})``
        with 1-D arrays, or ``None`` without a wear law."""
        h = self.scalars.get("history")
        if h is None or not h.get("wear_cycles"):
            return None
        import numpy as np

        saved = {
            c["cycle"]: (np.array(c["profile_x_m"]), np.array(c["profile_y_m"]))
            for c in h["wear_cycles"]
            if c["profile_x_m"]
        }
        return self.coordinates_m()[0], saved

    def __repr__(self):
        s = self.scalars
        return (
            f"Result({s['material']}/{s['surface']}/{s['angle_deg']}°: "
            f"a = {s['contact_radius_m']:.4e} m, c = {s['stick_radius_m']:.4e} m, "
            f"mu_a = {s['mu_a']}, status = {s['status']})"
        )


def _table_column(rows, get, dtype):
    """The 1-D array of ``get(row)`` over ``rows`` (a table's column)."""
    import numpy as np

    return np.array([get(r) for r in rows], dtype=dtype)


def solve(cfg, material=None, surface=None, angle_deg=None, indenter=None):
    """Solve one case of ``cfg`` in this process (what ``mpcontact solve`` does,
    without writing files) and return a :class:`Result`.

    ``material``, ``surface`` and ``angle_deg`` default to the sweep's first.
    ``indenter`` is the ball (``"rigid"``, a preset such as ``"steel"`` or a
    ``[materials.*]`` name), like ``mpcontact solve --indenter``; it defaults
    to the first of ``sweep.indenters``, else ``indenter.material``, else rigid.
    ``surface`` is a name (preset or ``[surfaces.*]``) or an ``(n, n)`` array
    of heights in µm, rows along y — the same as a ``shape = "heightmap"``
    surface reading that array from a ``.npy`` file — or a measured scan:
    a SurfaceTopography topography object or a ``pathlib.Path`` to any file
    it reads (or an ``.x3p``), solved as the config's ``shape = "scan"``
    with its default preparation (plane levelling, missing points refused;
    :func:`with_scan` sets them).

    The GIL is released while solving; Ctrl-C stops the solve with
    ``KeyboardInterrupt``. Raises ``ValueError`` for a bad argument or
    config (naming the key) and :class:`SolveError` for a case the solver
    could not solve.
    """
    heights = None
    name = surface
    if hasattr(surface, "heights") or isinstance(surface, os.PathLike):
        cfg = with_scan(cfg, "scan", surface, sweep=False)
        name = "scan"
    elif surface is not None and not isinstance(surface, str):
        import numpy as np

        heights = np.ascontiguousarray(surface, dtype=np.float64)
        if heights.ndim != 2:
            raise ValueError(
                f"surface: a height array must be 2-D (n, n), got shape {heights.shape}"
            )
        name = None
    if angle_deg is not None:
        angle_deg = float(angle_deg)
    scalars, fields, stress = _native.solve(
        cfg,
        material=material,
        surface=name,
        heights=heights,
        angle_deg=angle_deg,
        indenter=indenter,
    )
    return Result(scalars, fields, stress)


def kernel(material, angles_deg, cfg=None):
    """The Fourier-domain surface compliance H(θ) of ``material`` at each
    angle (degrees), 1/Pa: complex128 array ``(m, 3, 3)``, the matrices
    ``mpcontact kernel`` prints. ``material`` is a preset name, or a
    ``[materials.*]`` name of ``cfg``."""
    import numpy as np

    angles = np.atleast_1d(np.asarray(angles_deg, dtype=np.float64))
    if angles.ndim != 1:
        raise ValueError(f"angles_deg: expected a 1-D list of angles, got shape {angles.shape}")
    return _native.kernel(material, angles.tolist(), cfg)


def materials():
    """The preset material names (``mpcontact materials``)."""
    return _native.materials()


class RunResult:
    """The outputs of a sweep.

    ``results``: ``results.csv`` as a dict of numpy columns (one entry per
    case; numbers as float64, empty cells NaN, text as str arrays).
    ``curves``: ``curves.csv`` the same way. ``summary``: the run's tallies
    and timings (summary.json without the config echo). ``out``: the output
    directory with every file ``mpcontact run`` writes.
    ``fretting_map`` and ``fretting_transitions``: ``fretting_map.csv`` and
    ``fretting_transitions.csv`` the same way in a sweep with
    ``sweep.amplitudes_um`` (a fretting map), ``None`` otherwise.
    ``orientations``: ``orientations.csv`` the same way in a sweep with
    ``sweep.orientations`` (the numbers behind the inverse-pole-figure maps
    under ``out / "ipf"``), ``None`` otherwise.
    """

    __slots__ = (
        "results",
        "curves",
        "summary",
        "out",
        "fretting_map",
        "fretting_transitions",
        "orientations",
    )

    def __init__(
        self,
        results,
        curves,
        summary,
        out,
        fretting_map=None,
        fretting_transitions=None,
        orientations=None,
    ):
        self.results = results
        self.curves = curves
        self.summary = summary
        self.out = out
        self.fretting_map = fretting_map
        self.fretting_transitions = fretting_transitions
        self.orientations = orientations

    def __repr__(self):
        s = self.summary
        return (
            f"RunResult({s.get('total')} cases: {s.get('ok')} ok, "
            f"{s.get('not_converged')} not converged, {s.get('failed')} failed → {self.out})"
        )


def run(cfg, workers=2, out=None, resume=False, progress=True, save_fields=False):
    """Run the sweep of ``cfg`` on ``workers`` worker processes — the
    coordinator and workers of ``mpcontact run`` — and return a
    :class:`RunResult`.

    ``out``: output directory (a new temporary directory when ``None``);
    it gets the same files as ``mpcontact run --out``. ``resume`` continues
    an interrupted sweep in ``out``. ``progress`` shows the progress bar on
    stderr. ``save_fields`` also writes ``fields/<case>/*.npy``.

    This process acts as the coordinator; each worker is this Python
    interpreter running the Rust worker (see ``mpcontact._worker``).
    Ctrl-C stops the sweep with ``KeyboardInterrupt``. A case that fails
    is a row with status ``failed``; a run that cannot go on (output
    directory, lock, memory, workers) raises ``RuntimeError``.
    """
    if int(workers) < 1:
        raise ValueError(f"workers must be at least 1, got {workers}")
    if out is None:
        out = tempfile.mkdtemp(prefix="mpcontact-run-")
    out = Path(out)
    _warn_unresolved(cfg)
    program, args = _worker_command()
    summary = _native.run(
        cfg, int(workers), str(out), bool(resume), not progress, bool(save_fields), program, args
    )
    return RunResult(
        results=_read_csv(out / "results.csv"),
        curves=_read_csv(out / "curves.csv"),
        summary=summary,
        out=out,
        fretting_map=_read_csv_if(out / "fretting_map.csv"),
        fretting_transitions=_read_csv_if(out / "fretting_transitions.csv"),
        orientations=_read_csv_if(out / "orientations.csv"),
    )


def _warn_unresolved(cfg):
    """Warns, as ``mpcontact run`` does on stderr, of each pattern of the
    sweep that the grid does not resolve."""
    import warnings

    for text in cfg.unresolved_patterns():
        warnings.warn(text, UserWarning, stacklevel=3)


def _worker_command():
    """How a worker is started: this interpreter, importing this very
    installation (its parent directory goes first on ``sys.path``, so the
    current directory or a source tree cannot shadow it)."""
    if not sys.executable or not os.access(sys.executable, os.X_OK):
        raise RuntimeError(
            "mpcontact.run needs sys.executable (the Python interpreter) to start its workers"
        )
    parent = str(Path(__file__).resolve().parent.parent)
    code = (
        "import sys; sys.path.insert(0, {!r}); "
        "from mpcontact._worker import main; main()".format(parent)
    )
    return sys.executable, ["-c", code]


def _read_csv_if(path):
    """:func:`_read_csv` of ``path`` if the run wrote it, else ``None``."""
    return _read_csv(path) if path.exists() else None


def _read_csv(path):
    """A CSV written by the runner as a dict of numpy columns."""
    import numpy as np

    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        return {}
    header, body = rows[0], rows[1:]
    columns = {}
    for j, name in enumerate(header):
        cells = [r[j] if j < len(r) else "" for r in body]
        columns[name] = _column(cells, np)
    return columns


def _column(cells, np):
    """float64 when every cell is a number (empty → NaN; the angle "30" is a
    number like any other), else str."""
    try:
        return np.array([float(c) if c != "" else np.nan for c in cells], dtype=np.float64)
    except ValueError:
        return np.array(cells, dtype=str)
