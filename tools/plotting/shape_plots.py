#!/usr/bin/python3
"""The operating deflection shape of a sector forced response (matplotlib, meshio).

plot_shape(result_dir): frf.vtu -> shape.png

The largest peak's shape (the one frf.pvd animates): the sector's nodes at the
instant of the largest response, displaced by the shape scaled to a tenth of the sector's
size, coloured by the amplitude over the period (max_t |u(t)|, in um), seen from two sides;
the undeformed sector in grey behind it; in mm. ParaView shows the same from frf.vtu and frf.pvd.
"""
import csv
import math
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def plot_shape(result_dir):
    """Reads result_dir/frf.vtu, frf.pvd and contact_map.csv and writes result_dir/shape.png;
    returns its path (None without meshio or without shapes)."""
    try:
        import meshio
        import numpy as np
    except ImportError:
        return None
    from plotting import result_name

    # The largest peak's shape is the one frf.pvd animates; its frequency is in contact_map.csv
    # (run.json is written after the plots).
    pvd = os.path.join(result_dir, "frf.pvd")
    if not os.path.exists(pvd):
        return None
    with open(pvd) as f:
        first = [line for line in f if 'file="' in line]
    if not first:
        return None
    name = os.path.basename(first[0].split('file="')[1].split('"')[0]).rsplit("_t", 1)[0]
    frequency = None
    with open(os.path.join(result_dir, "contact_map.csv"), newline="") as f:
        for row in csv.DictReader(f):
            if row["shape"] == name:
                frequency = float(row["frequency_hz"])
                break
    mesh = meshio.read(os.path.join(result_dir, "frf.vtu"))
    x = mesh.points
    prefix = name + "_u_h"
    harmonics = sorted(int(k[len(prefix):-len("_re_m")]) for k in mesh.point_data
                       if k.startswith(prefix) and k.endswith("_re_m"))
    u = [mesh.point_data[f"{name}_u_h{n}_re_m"] + 1j * mesh.point_data[f"{name}_u_h{n}_im_m"] for n in harmonics]
    amplitude = np.asarray(mesh.point_data[f"{name}_amplitude_m"]).reshape(-1)
    # The instant of the largest displacement of any node.
    thetas = np.linspace(0.0, 2.0 * math.pi, 96, endpoint=False)
    best, best_theta = -1.0, 0.0
    for t in thetas:
        ut = sum((un * np.exp(1j * n * t)).real for n, un in zip(harmonics, u))
        m = np.linalg.norm(ut, axis=1).max()
        if m > best:
            best, best_theta = m, t
    ut = sum((un * np.exp(1j * n * best_theta)).real for n, un in zip(harmonics, u))
    size = np.linalg.norm(x.max(axis=0) - x.min(axis=0))
    scale = 0.1 * size / best if best > 0 else 0.0
    xd = x + scale * ut
    fig, axes = plt.subplots(1, 2, figsize=(11, 6.5))
    order = np.argsort(amplitude)  # the largest amplitudes drawn last, on top
    for ax, (i, j, label) in zip(axes, ((0, 1, "seen along z"), (2, 1, "seen along x"))):
        ax.scatter(1e3 * x[:, i], 1e3 * x[:, j], s=1, c="0.82")
        sc = ax.scatter(1e3 * xd[order, i], 1e3 * xd[order, j], s=3, c=1e6 * amplitude[order], cmap="viridis")
        ax.set_xlabel("xyz"[i] + " [mm]")
        ax.set_ylabel("xyz"[j] + " [mm]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_title(label, fontsize=9)
    fig.colorbar(sc, ax=list(axes), shrink=0.8, label="amplitude over the period [\u00b5m]")
    at = f" at {frequency:.6g} Hz" if frequency is not None else ""
    fig.suptitle(f"{result_name(result_dir)}: shape{at} ({name}), largest amplitude {1e6 * amplitude.max():.3g} "
                 f"\u00b5m; displacements x {scale:.3g}")
    out = os.path.join(result_dir, "shape.png")
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out
