#!/usr/bin/python3
"""Hysteresis loops of one contact pair from `shroudsim contact` (matplotlib).

plot_contact(result_dir): contact.json -> contact_loops.png

Three panels over one steady period: tangential force Tx against x, Ty against y (the
friction loops; their areas are the energy each direction dissipates per cycle), and the
normal force N against z (a unilateral spring: no area). Units: displacements in um,
forces in N. The title names the model, the tangential update and the dissipated energy.
"""
import json
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def _closed(values):
    """The samples of one period with the first repeated at the end (a closed loop)."""
    return list(values) + list(values[:1])


def plot_contact(result_dir):
    """Reads result_dir/contact.json and writes result_dir/contact_loops.png; returns its path."""
    with open(os.path.join(result_dir, "contact.json")) as f:
        data = json.load(f)
    time = data["time"]
    um = 1e6
    panels = [("x", "tx", "x [um]", "Tx [N]"), ("y", "ty", "y [um]", "Ty [N]"), ("z", "n", "z [um]", "N [N]")]
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2))
    for ax, (disp, force, xlabel, ylabel) in zip(axes, panels):
        xs = [v * um for v in _closed(time[disp])]
        fs = _closed(time[force])
        ax.plot(xs, fs, "-", lw=1.4, color="tab:blue")
        if xs:
            ax.plot(xs[0], fs[0], "o", ms=4, color="tab:red", label="t = 0")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.grid(True, alpha=0.3)
        ax.axhline(0.0, color="k", lw=0.5)
        ax.axvline(0.0, color="k", lw=0.5)
    axes[0].legend(loc="best", fontsize=8)
    title = "{} / {}: H = {}, N = {}, {} periods{}, dissipated {:.4g} J/cycle".format(
        data.get("model", "?"),
        data.get("tangential_update", "?"),
        data.get("harmonics", "?"),
        data.get("time_samples", "?"),
        data.get("periods", "?"),
        "" if data.get("converged_periodic", True) else " (NOT periodic)",
        data.get("dissipated_energy_j", float("nan")),
    )
    fig.suptitle(title)
    fig.tight_layout()
    out = os.path.join(result_dir, "contact_loops.png")
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


if __name__ == "__main__":
    import sys

    for d in sys.argv[1:] or ["."]:
        print(plot_contact(d))
