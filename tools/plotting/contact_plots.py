#!/usr/bin/python3
"""Hysteresis loops of one contact pair from `shroudsim contact` (matplotlib).

plot_contact(result_dir): contact.json -> contact_loops.png
plot_contact_map(result_dir): contact_map.csv -> contact.png (what each pair does at each shape)

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


def plot_contact_map(result_dir):
    """Reads result_dir/contact_map.csv (`shroudsim frf`) and writes result_dir/contact.png;
    returns its path.

    One row of panels per shape (resonance peaks first, at most four shapes): the energy each
    contact pair dissipates per cycle, on the shroud face where the pairs have positions (a
    sector: the face seen along its mean normal, in mm) or per pair (lumped elements), and the
    fractions of the period each pair sticks, slips and is open.
    """
    import csv

    from plotting import result_name
    from plotting.frf_plots import scale_unit

    with open(os.path.join(result_dir, "contact_map.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        return None
    shapes = []
    for r in rows:
        if r["shape"] not in shapes:
            shapes.append(r["shape"])
    shapes = shapes[:4]
    placed = rows[0]["x_m"] != ""
    # Energies at round-off of the largest (a stuck pair's loop has no area) are drawn as zero.
    floor = 1e-9 * max(abs(float(r["energy_per_cycle_j"])) for r in rows)
    fig, axes = plt.subplots(len(shapes), 2, figsize=(12, 3.8 * len(shapes)), squeeze=False)
    for row, shape in enumerate(shapes):
        sel = [r for r in rows if r["shape"] == shape]
        pairs = [int(r["pair"]) for r in sel]
        energy = [float(r["energy_per_cycle_j"]) for r in sel]
        energy = [e if abs(e) > floor else 0.0 for e in energy]
        factor, unit = scale_unit(energy, "J")
        if not any(energy):
            factor = 1.0
        ax = axes[row][0]
        title = f"{shape} at {float(sel[0]['frequency_hz']):.6g} Hz: energy per cycle, total {sum(energy) / factor:.3g} {unit}"
        if placed:
            # The face's own plane: its two principal directions through the pairs' positions.
            pts = [[float(r[k]) for k in ("x_m", "y_m", "z_m")] for r in sel]
            c = [sum(p[k] for p in pts) / len(pts) for k in range(3)]
            d = [[p[k] - c[k] for k in range(3)] for p in pts]
            u, v = _principal_plane(d)
            xs = [1e3 * sum(a * b for a, b in zip(p, u)) for p in d]
            ys = [1e3 * sum(a * b for a, b in zip(p, v)) for p in d]
            sc = ax.scatter(xs, ys, c=[e / factor for e in energy], cmap="inferno", s=90, edgecolors="k")
            fig.colorbar(sc, ax=ax, label=f"energy per cycle [{unit}]")
            for p, x, y in zip(pairs, xs, ys):
                if len(pairs) <= 30:
                    ax.annotate(str(p), (x, y), textcoords="offset points", xytext=(5, 5), fontsize=7)
            ax.set_xlabel("along the face, first direction [mm]")
            ax.set_ylabel("second direction [mm]")
            ax.set_aspect("equal", adjustable="datalim")
        else:
            ax.bar(pairs, [e / factor for e in energy], color="tab:red")
            ax.set_xlabel("contact pair")
            if len(pairs) <= 30:
                ax.set_xticks(pairs)
            ax.set_ylabel(f"energy per cycle [{unit}]")
        ax.set_title(title, fontsize=9)
        ax = axes[row][1]
        stick = [float(r["stick_fraction"]) for r in sel]
        slip = [float(r["slip_fraction"]) for r in sel]
        opened = [float(r["open_fraction"]) for r in sel]
        ax.bar(pairs, stick, color="tab:blue", label="stick")
        ax.bar(pairs, slip, bottom=stick, color="tab:orange", label="slip")
        ax.bar(pairs, opened, bottom=[a + b for a, b in zip(stick, slip)], color="0.75", label="open")
        ax.set_ylim(0, 1)
        ax.set_xlabel("contact pair")
        ax.set_ylabel("fraction of the period")
        ax.legend(loc="upper right", fontsize=8, ncol=3)
        ax.set_title(f"{shape}: stick, slip and separation per pair", fontsize=9)
        if len(pairs) <= 30:
            ax.set_xticks(pairs)
    fig.suptitle(f"Contact map: {result_name(result_dir)}")
    fig.tight_layout()
    out = os.path.join(result_dir, "contact.png")
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out


def _principal_plane(d):
    """Two orthonormal directions spanning the largest spread of the centred points d."""
    import numpy as np

    a = np.array(d, dtype=float)
    if len(a) < 2 or not np.any(a):
        return [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]
    _, _, vt = np.linalg.svd(a, full_matrices=True)
    return list(vt[0]), list(vt[1])
