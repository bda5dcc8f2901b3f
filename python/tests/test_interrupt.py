"""Ctrl-C: a long solve and a running sweep stop with KeyboardInterrupt,
the sweep's workers are gone, Python's own Ctrl-C works afterwards, and
the interrupted sweep resumes to every case. Each runs in a child Python
(SIGINT to this process would hit pytest)."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from conftest import REPO

# A child that takes Ctrl-C like an interactive Python even when started
# from a shell or CI that ignores SIGINT for background jobs.
PRELUDE = """
import json, signal, sys, time
import mpcontact
signal.signal(signal.SIGINT, signal.default_int_handler)
"""

LONG_SOLVE = PRELUDE + """
cfg = mpcontact.Config.from_toml(sys.argv[1])
cfg.set("grid.points", 1024)
cfg.set("solver.coupling", True)   # ~6 s of CPU, 3.5 s on 2 threads (512² took 1.6 s
                                   # since round 5 and could end before the signal)
print("start", flush=True)
# CPU time, not wall time: on a loaded machine the solve may get little CPU,
# and what matters is how much of its ~10 s of work it did before stopping.
t = time.process_time()
try:
    mpcontact.solve(cfg)
    print("finished", time.process_time() - t, flush=True)
except KeyboardInterrupt:
    print("interrupted", time.process_time() - t, flush=True)
# The solver's thread is usable again, and Ctrl-C is Python's again.
small = mpcontact.Config.from_toml(sys.argv[1])
small.set("grid.points", 64)
small.set("grid.spacing_um", 6.0)
print("after", mpcontact.solve(small).scalars["status"], flush=True)
try:
    signal.raise_signal(signal.SIGINT)
    time.sleep(5)
except KeyboardInterrupt:
    print("python ctrl-c ok", flush=True)
"""


def start(code, *args):
    return subprocess.Popen(
        [sys.executable, "-c", code, *map(str, args)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=REPO,
    )


def test_ctrl_c_stops_a_long_solve_with_keyboard_interrupt():
    p = start(LONG_SOLVE, REPO / "configs" / "mindlin-uncoupled.toml")
    assert p.stdout.readline().strip() == "start"
    time.sleep(1.5)
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=600)
    lines = out.splitlines()
    assert lines[0].startswith("interrupted"), (out, err)
    # The solve (~10 s of CPU) stopped within its next iterations (at most
    # 1.5 s of CPU had gone into it when the signal came), not at its end.
    assert float(lines[0].split()[1]) < 4.0, lines[0]
    assert lines[1:] == ["after ok", "python ctrl-c ok"], (out, err)


SWEEP = PRELUDE + """
cfg = mpcontact.Config.from_dict({
    "grid": {"points": 256, "spacing_um": 1.5},
    "indenter": {"radius_mm": 18.0},
    "load": {"normal_n": 20.0, "friction": 0.3, "tangential_ratio": 0.6},
    "sweep": {"materials": ["Fe", "Cu"], "angles_deg": {"start": 0, "stop": 150, "step": 30}},
})
out = sys.argv[1]
try:
    r = mpcontact.run(cfg, workers=2, out=out, progress=False)
    print("finished", flush=True)
except KeyboardInterrupt as e:
    print("interrupted:", e, flush=True)
r = mpcontact.run(cfg, workers=2, out=out, resume=True, progress=False)
print(json.dumps({"total": r.summary["total"], "resumed": r.summary["resumed"],
                  "status": sorted(set(r.results["status"]))}), flush=True)
"""


def children(pid):
    try:
        text = Path(f"/proc/{pid}/task/{pid}/children").read_text()
    except OSError:
        return set()
    return {int(c) for c in text.split()}


def test_ctrl_c_stops_a_sweep_its_workers_exit_and_it_resumes(tmp_path):
    out = tmp_path / "sweep"
    p = start(SWEEP, out)
    journal = out / "journal.jsonl"
    deadline = time.time() + 600  # generous: a loaded machine may give it little CPU
    # Interrupt once a case is recorded and both workers are up.
    while time.time() < deadline:
        if journal.is_file() and '"kind":"case"' in journal.read_text():
            break
        time.sleep(0.05)
    workers = children(p.pid)
    assert len(workers) == 2, workers
    p.send_signal(signal.SIGINT)
    line = p.stdout.readline()
    assert line.startswith("interrupted:") and "resume=True" in line, line + p.stderr.read()
    assert not any(os.path.exists(f"/proc/{w}") for w in workers), "workers left behind"
    rest, err = p.communicate(timeout=600)
    assert rest.strip(), err
    summary = json.loads(rest.splitlines()[-1])
    assert summary["total"] == 12 and summary["status"] == ["ok"], (rest, err)
    assert 1 <= summary["resumed"] < 12
