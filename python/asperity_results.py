"""Read an asperity run's output folder into numpy arrays.

A run (scripts/joint.lua, rev.lua, demo.lua, ...) writes into its `out` folder:

- summary.json                 the run's parameters and results
- NAME.h5 (+ NAME.csv)         series: one 1-D dataset per column, each with a `units`
                               attribute; the file's attributes (stress_scale, parameter_*)
- NAME_000000.h5 ... NAME.xdmf particle snapshots: /particles/{id, position, velocity, radius,
                               group, tag, force, angular_velocity, displacement},
                               /contacts/..., /bonds/...; root attributes step, time,
                               index_time (what the XDMF time is, e.g. the shear displacement
                               in mm) and the script's own

Usage::

    from asperity_results import Run
    run = Run("out/joint")
    shear = run.series("shear")           # Series: shear["shear_stress_mpa"] is a numpy array
    shear.units["shear_stress_mpa"]       # 'MPa (scaled to rock)'
    run.summary["peak_shear_stress_mpa"]
    for snap in run.snapshots("joint"):   # in order; snap.time is the XDMF time
        snap.particles["displacement"]    # (n, 3) array, m

Needs h5py and numpy (Debian: python3-h5py python3-numpy). Run as a program it prints what
the folder holds: python3 asperity_results.py out/joint
"""

import json
import os
import re
import sys

import h5py
import numpy as np


def _attr(value):
    """HDF5 attribute -> Python value (bytes to str, 0-d arrays to scalars)."""
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, np.ndarray) and value.shape == ():
        return value.item()
    if isinstance(value, np.generic):
        return value.item()
    return value


class Series:
    """Columns of a series file: series[name] -> 1-D array; .units[name]; .attrs (the file's)."""

    def __init__(self, path):
        self.path = path
        with h5py.File(path, "r") as f:
            self.attrs = {k: _attr(v) for k, v in f.attrs.items()}
            order = self.attrs.get("columns")
            names = order.split(",") if order else sorted(f.keys())
            self.columns = {}
            self.units = {}
            for name in names:
                dataset = f[name]
                self.columns[name] = dataset[()]
                self.units[name] = _attr(dataset.attrs.get("units", ""))

    def __getitem__(self, name):
        return self.columns[name]

    def __contains__(self, name):
        return name in self.columns

    def names(self):
        return list(self.columns)

    def __len__(self):
        return len(next(iter(self.columns.values()))) if self.columns else 0

    def parameters(self):
        """The run's parameters stored with the series (attributes parameter_NAME)."""
        return {k[len("parameter_"):]: v for k, v in self.attrs.items() if k.startswith("parameter_")}

    def label(self, name):
        """'shear_stress_mpa (MPa (scaled to rock))': a column with its unit, for an axis."""
        unit = self.units.get(name, "")
        return f"{name} ({unit})" if unit else name


class Snapshot:
    """One snapshot file: .particles, .contacts, .bonds (dicts of arrays), .attrs, .time, .keys."""

    def __init__(self, path):
        self.path = path
        self.particles, self.contacts, self.bonds = {}, {}, {}
        with h5py.File(path, "r") as f:
            self.attrs = {k: _attr(v) for k, v in f.attrs.items()}
            for group, into in (("particles", self.particles), ("contacts", self.contacts), ("bonds", self.bonds)):
                if group in f:
                    for name, dataset in f[group].items():
                        into[name] = dataset[()]
            self.keys = {k: _attr(v) for k, v in f["particles"].attrs.items()} if "particles" in f else {}
        # The time the XDMF index gives this snapshot: the script's (e.g. shear displacement, mm)
        # when it set one, else the simulated time in s.
        self.time = self.attrs.get("index_time", self.attrs.get("time"))
        self.time_label = self.attrs.get("index_time_label", "simulated time (s)")

    def __len__(self):
        return len(self.particles.get("id", ()))


class Run:
    """An output folder: .summary (dict or None), .series(name), .snapshots(name)."""

    def __init__(self, folder):
        if not os.path.isdir(folder):
            raise FileNotFoundError(f"no run folder {folder!r}")
        self.folder = folder
        path = os.path.join(folder, "summary.json")
        self.summary = None
        if os.path.exists(path):
            with open(path) as f:
                # the engine writes non-finite numbers as null, which json reads as None
                self.summary = json.load(f)

    def _snapshot_files(self, name):
        pattern = re.compile(re.escape(name) + r"_(\d{6,})\.h5$")
        found = []
        for file in os.listdir(self.folder):
            m = pattern.match(file)
            if m:
                found.append((int(m.group(1)), file))
        return [os.path.join(self.folder, f) for _, f in sorted(found)]

    def series_names(self):
        """Series files in the folder (HDF5 files that are neither snapshots nor checkpoints)."""
        names = []
        for file in sorted(os.listdir(self.folder)):
            if not file.endswith(".h5") or re.search(r"_\d{6,}\.h5$", file):
                continue
            with h5py.File(os.path.join(self.folder, file), "r") as f:
                if "columns" in f.attrs:
                    names.append(file[:-3])
        return names

    def snapshot_names(self):
        """Snapshot series in the folder (one per XDMF index of particles)."""
        return sorted(file[:-5] for file in os.listdir(self.folder)
                      if file.endswith(".xdmf") and not file.endswith(("_contacts.xdmf", "_bonds.xdmf")))

    def series(self, name):
        return Series(os.path.join(self.folder, name + ".h5"))

    def snapshots(self, name):
        """Every snapshot of the series NAME, in the order written."""
        files = self._snapshot_files(name)
        if not files:
            raise FileNotFoundError(f"no snapshots {name}_NNNNNN.h5 in {self.folder!r}")
        return [Snapshot(f) for f in files]


def describe(folder):
    run = Run(folder)
    print(f"run {folder}")
    if run.summary is not None:
        print(f"  summary.json: {len(run.summary)} entries")
    for name in run.series_names():
        s = run.series(name)
        print(f"  series {name}: {len(s)} rows; " + ", ".join(s.label(c) for c in s.names()))
    for name in run.snapshot_names():
        snaps = run.snapshots(name)
        times = ", ".join(f"{s.time:.4g}" for s in snaps)
        print(f"  snapshots {name}: {len(snaps)} at {snaps[0].time_label} = {times}; "
              f"{len(snaps[-1])} particles, fields " + ", ".join(snaps[-1].particles))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: python3 asperity_results.py RUN_FOLDER")
    describe(sys.argv[1])
