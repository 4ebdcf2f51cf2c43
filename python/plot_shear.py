"""Example: the shear curve of a joint run (scripts/joint.lua) with matplotlib.

    python3 python/plot_shear.py out/joint            # writes out/joint/shear_curve.png
    python3 python/plot_shear.py out/joint my.png

Shear stress and dilatancy against shear displacement, stacked, with the peak and the residual
of summary.json marked. Needs python3-h5py, python3-numpy and python3-matplotlib.
"""

import os
import sys

import matplotlib

matplotlib.use("Agg")  # files only: works without a display
import matplotlib.pyplot as plt
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from asperity_results import Run  # noqa: E402


def plot_shear(folder, png):
    run = Run(folder)
    shear = run.series("shear")
    u = shear["displacement"]
    tau = shear["shear_stress_mpa"]
    dilatancy = shear["dilatancy"]
    s = run.summary or {}
    p = shear.parameters()

    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(10, 7), constrained_layout=True)
    top.plot(u, tau, color="tab:blue", label="shear stress")
    if "peak_shear_stress_mpa" in s:
        top.plot(s["peak_displacement_mm"], s["peak_shear_stress_mpa"], "o", color="tab:red",
                 label=f"peak {s['peak_shear_stress_mpa']:.2f} MPa at {s['peak_displacement_mm']:.2f} mm")
    if "residual_shear_stress_mpa" in s:
        window = s.get("residual_window_mm", 0.5)
        top.hlines(s["residual_shear_stress_mpa"], u[-1] - window, u[-1], color="tab:orange", lw=3,
                   label=f"residual {s['residual_shear_stress_mpa']:.2f} MPa (last {window:g} mm)")
    top.set_ylabel("shear stress (MPa, scaled to rock)")
    top.legend(loc="upper left", bbox_to_anchor=(1.02, 1), borderaxespad=0)
    top.grid(alpha=0.3)
    bottom.plot(u, dilatancy, color="tab:green")
    bottom.set_xlabel("shear displacement (mm)")
    bottom.set_ylabel("dilatancy (mm)")
    bottom.grid(alpha=0.3)
    title = f"{p.get('surface', '')}, {p.get('model', '')} model, {p.get('stress', '')} MPa normal stress"
    fig.suptitle(title)
    fig.savefig(png, dpi=100)
    plt.close(fig)
    return np.max(tau)


if __name__ == "__main__":
    if len(sys.argv) not in (2, 3):
        sys.exit("usage: python3 plot_shear.py RUN_FOLDER [PNG]")
    folder = sys.argv[1]
    png = sys.argv[2] if len(sys.argv) == 3 else os.path.join(folder, "shear_curve.png")
    plot_shear(folder, png)
    print(f"wrote {png}")
