"""Test of asperity_results.py on a run's output folder (run by ctest).

    python3 python/check_reader.py DEMO_FOLDER            # scripts/demo.lua's output
    python3 python/check_reader.py JOINT_FOLDER --joint   # scripts/joint.lua's, and plot_shear.py

Asserts that what the reader returns agrees with the files' other copies (the CSV, summary.json,
the XDMF index) and with the physics the script wrote down.
"""

import csv
import os
import re
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from asperity_results import Run  # noqa: E402


def check_series_against_csv(run, name):
    s = run.series(name)
    with open(os.path.join(run.folder, name + ".csv")) as f:
        rows = list(csv.reader(f))
    header, values = rows[0], np.array([[float(v) for v in r] for r in rows[1:]])
    assert len(header) == len(s.names()), (header, s.names())
    for j, name_j in enumerate(s.names()):
        unit = s.units[name_j]
        assert header[j] == (f"{name_j} [{unit}]" if unit else name_j), (header[j], name_j, unit)
        assert np.allclose(values[:, j], s[name_j], rtol=1e-12, atol=0, equal_nan=True), name_j
    return s


def check_snapshots(run, name):
    snaps = run.snapshots(name)
    with open(os.path.join(run.folder, name + ".xdmf")) as f:
        xdmf = f.read()
    times = [float(t) for t in re.findall(r'<Time Value="([^"]+)"', xdmf)]
    assert len(times) == len(snaps), (len(times), len(snaps))
    for snap, t in zip(snaps, times):
        assert snap.time == t, (snap.time, t)
        n = len(snap)
        for field, cols in (("position", 3), ("velocity", 3), ("force", 3), ("angular_velocity", 3),
                            ("displacement", 3), ("radius", 1), ("group", 1), ("tag", 1)):
            a = snap.particles[field]
            assert a.shape == ((n, cols) if cols > 1 else (n,)), (field, a.shape, n)
    first, last = snaps[0], snaps[-1]
    assert np.all(first.particles["displacement"] == 0), "displacements count from the first snapshot"
    # displacement = position now - position in the first snapshot, particle by particle (by id)
    where = {i: k for k, i in enumerate(first.particles["id"])}
    rows = [where[i] for i in last.particles["id"]]
    expected = last.particles["position"] - first.particles["position"][rows]
    assert np.allclose(last.particles["displacement"], expected, rtol=0, atol=1e-15)
    return snaps


def main():
    folder, joint = sys.argv[1], "--joint" in sys.argv[2:]
    run = Run(folder)
    assert run.summary is not None, "summary.json"
    if not joint:
        energy = check_series_against_csv(run, "energy")
        assert len(energy) > 10 and np.all(np.diff(energy["time"]) > 0), "time increases"
        snaps = check_snapshots(run, "particles")
        # the demo's particles fall: the last snapshot is lower than the first, and its XDMF
        # time is the simulated time
        assert snaps[-1].particles["displacement"][:, 2].mean() < 0, "the particles fell"
        assert snaps[-1].time_label == "simulated time (s)" and snaps[-1].time == snaps[-1].attrs["time"]
        print(f"PASS demo: {len(energy)} rows, {len(snaps)} snapshots of {len(snaps[-1])} particles")
        return
    shear = check_series_against_csv(run, "shear")
    closure = check_series_against_csv(run, "closure")
    s = run.summary
    assert shear.units["shear_stress_mpa"] == "MPa (scaled to rock)" and shear.units["shear_stress"] == "Pa (model)"
    scale = shear.attrs["stress_scale"]
    assert np.allclose(shear["shear_stress"] * scale / 1e6, shear["shear_stress_mpa"], rtol=1e-12)
    assert shear.parameters()["stress"] == s["parameters"]["stress"], "parameters as attributes"
    assert np.max(shear["shear_stress_mpa"]) == s["peak_shear_stress_mpa"], "the peak is the curve's maximum"
    assert closure.units["closure"] == "mm" and closure["closure"][-1] == s["closure_mm"]
    snaps = check_snapshots(run, "joint")
    assert snaps[0].time == 0 and snaps[-1].time == shear["displacement"][-1], "XDMF time: shear displacement, mm"
    tags = snaps[-1].particles["tag"]
    assert set(np.unique(tags)) <= {1, 2} and len(tags) == s["n_particles"], "only the two halves are drawn"
    upper = tags == 2
    moved = -snaps[-1].particles["displacement"][upper, 0].max() if s["parameters"]["direction"] == "x" else None
    if moved is not None:
        assert moved > 0.5e-3 * s["parameters"]["shear"], f"the upper half moved only {moved:.3g} m"
    assert "group_key" in snaps[-1].keys and "tag_key" in snaps[-1].keys
    png = os.path.join(folder, "shear_curve_test.png")
    import plot_shear
    peak = plot_shear.plot_shear(folder, png)
    assert peak == s["peak_shear_stress_mpa"] and os.path.getsize(png) > 10000, "the example plots the curve"
    print(f"PASS joint: {len(shear)} shear rows, {len(snaps)} snapshots, peak {peak:.3f} MPa, "
          f"upper half moved at least {moved if moved is not None else float('nan'):.3g} m")


if __name__ == "__main__":
    main()
