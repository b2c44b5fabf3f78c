#!/usr/bin/python3
"""Plots of the modal results of a shroudsim result folder (matplotlib).

plot_nd_map(result_dir):   modes.csv                     -> nd_map.png
plot_campbell(result_dir): campbell.csv, crossings.csv   -> campbell.png
plot_static_contact(result_dir): static_contact.csv     -> contact_static.png

nd_map.png: natural frequency against nodal diameter, one line per mode family (the r-th
mode of every nodal diameter), left all families, right the lowest ten.
campbell.png: frequency against speed, one horizontal line per mode (colour = nodal
diameter), engine-order lines f = EO * rpm / 60, and the crossings where an engine order
meets a mode of the nodal diameter it excites.
"""
import json
import math
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from plotting import read_csv  # noqa: E402


def _families(rows):
    """{nodal_diameter: [f_1, f_2, ...]} from modes.csv rows (one harmonic index per ND)."""
    by_nd = {}
    seen_h = {}
    for r in rows:
        nd, h = int(r["nodal_diameter"]), int(r["harmonic_index"])
        if seen_h.setdefault(nd, h) != h:
            continue  # h and Nb - h have equal frequencies: keep one
        by_nd.setdefault(nd, []).append((int(r["mode"]), float(r["frequency_hz"])))
    return {nd: [f for _, f in sorted(v)] for nd, v in sorted(by_nd.items())}


def _shroud_note():
    """' (open shroud)' / ' (stuck shroud)' when plot.py was given --shroud."""
    s = os.environ.get("SHROUDSIM_PLOT_SHROUD")
    if s == "contact":
        return " (shroud pairs closed by the static contact tied)"
    return f" ({s} shroud)" if s else ""


def plot_nd_map(result_dir):
    fam = _families(read_csv(os.path.join(result_dir, "modes.csv")))
    nds = sorted(fam)
    n_modes = max(len(v) for v in fam.values())
    # All families, and beside them the lowest 10 when there are more (with 10 or fewer the
    # second panel would be the first again). The legend (10 families or fewer) stands right of
    # its panel, and the margins are fixed: placing it inside by its overlap with the lines and
    # tight_layout's measuring of every label were a third of the drawing time.
    counts = (n_modes, 10) if n_modes > 10 else (n_modes,)
    legend = counts[-1] <= 10
    width = (13 if len(counts) == 2 else 7.5) + (1.3 if legend else 0.0)
    fig, axes = plt.subplots(1, len(counts), figsize=(width, 6), squeeze=False)
    fig.subplots_adjust(left=0.75 / width, right=1 - (1.5 if legend else 0.3) / width, bottom=0.1, top=0.87,
                        wspace=0.9 / (width / len(counts)))
    for ax, count in zip(axes[0], counts):
        for r in range(count):
            xs = [nd for nd in nds if r < len(fam[nd])]
            ys = [fam[nd][r] for nd in xs]
            ax.plot(xs, ys, "o-", ms=3, lw=1, label=f"family {r + 1}" if count <= 10 else None)
        ax.set_xlabel("nodal diameter")
        ax.set_ylabel("frequency [Hz]")
        ax.set_xticks(nds)
        ax.grid(True, alpha=0.3)
        ax.set_title("all %d mode families" % count if count == n_modes else "lowest %d mode families" % count)
        if count <= 10:
            ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    fig.suptitle("Nodal diameter map" + _shroud_note())
    fig.savefig(os.path.join(result_dir, "nd_map.png"), dpi=120, pil_kwargs={"compress_level": 1})
    plt.close(fig)


def plot_campbell(result_dir):
    rows = read_csv(os.path.join(result_dir, "campbell.csv"))
    crossings_path = os.path.join(result_dir, "crossings.csv")
    crossings = read_csv(crossings_path) if os.path.exists(crossings_path) else []
    speeds = sorted({float(r["speed_rpm"]) for r in rows})
    s0, s1 = speeds[0], speeds[-1]
    lines = {}
    seen_h = {}
    for r in rows:
        nd, h = int(r["nodal_diameter"]), int(r["harmonic_index"])
        if seen_h.setdefault(nd, h) != h:
            continue
        lines.setdefault((nd, int(r["mode"])), []).append((float(r["speed_rpm"]), float(r["frequency_hz"])))
    eos = sorted({int(c["engine_order"]) for c in crossings})
    eo_max = max(eos) if eos else 1
    f_top = 1.15 * eo_max * s1 / 60.0
    if not eos:
        f_top = max(max(f for _, f in v) for v in lines.values())
    nds = sorted({nd for nd, _ in lines})
    cmap = plt.get_cmap("viridis", max(len(nds), 2))
    fig, ax = plt.subplots(figsize=(11, 7))
    for (nd, _), pts in sorted(lines.items()):
        pts.sort()
        if min(f for _, f in pts) > f_top:
            continue
        ax.plot([p[0] for p in pts], [p[1] for p in pts], color=cmap(nds.index(nd)), lw=1)
    for nd in nds:
        ax.plot([], [], color=cmap(nds.index(nd)), lw=2, label=f"ND {nd}")
    for e in eos:
        ax.plot([s0, s1], [e * s0 / 60.0, e * s1 / 60.0], "k--", lw=0.8)
        ax.annotate(f"EO {e}", (s1, e * s1 / 60.0), fontsize=8, xytext=(3, 0), textcoords="offset points",
                    va="center")
    if crossings:
        ax.plot([float(c["speed_rpm"]) for c in crossings], [float(c["frequency_hz"]) for c in crossings],
                "ro", mfc="none", ms=7, label="crossing (EO excites ND)")
    # A sweep that stopped (a mode diverged): say where, from run.json (or, while shroudsim
    # itself draws, before it writes run.json, from SHROUDSIM_CAMPBELL_STOPPED).
    failures = [os.environ["SHROUDSIM_CAMPBELL_STOPPED"]] if os.environ.get("SHROUDSIM_CAMPBELL_STOPPED") else []
    if not failures:
        try:
            with open(os.path.join(result_dir, "run.json")) as f:
                sweeps = json.load(f).get("campbell", {}).get("sweeps", [])
            failures = [w["failure"] for w in sweeps if "failure" in w]
        except (OSError, ValueError):
            failures = []
    if failures:
        why = ("a mode diverges (K + K_sigma - Omega^2 M_spin not positive definite)"
               if "not positive definite" in failures[0] else failures[0][:90])
        ax.text(0.99, 0.01, "sweep stopped beyond %g rpm: %s; see run.json" % (s1, why),
                transform=ax.transAxes, ha="right", va="bottom", fontsize=7, color="firebrick")
    ax.set_xlim(s0, s1 * 1.06)
    ax.set_ylim(0, f_top)
    ax.set_xlabel("speed [rpm]")
    ax.set_ylabel("frequency [Hz]")
    flat = all(max(f for _, f in pts) - min(f for _, f in pts) <= 1e-9 * max(f for _, f in pts) for pts in lines.values())
    ax.set_title(("Campbell diagram (frequencies independent of speed)" if flat else
                  "Campbell diagram (centrifugal stiffening and spin softening)") + _shroud_note())
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    fig.savefig(os.path.join(result_dir, "campbell.png"), dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    import sys

    for d in sys.argv[1:]:
        if os.path.exists(os.path.join(d, "modes.csv")):
            plot_nd_map(d)
        if os.path.exists(os.path.join(d, "campbell.csv")):
            plot_campbell(d)


def plot_static_contact(result_dir):
    """contact_static.png: contact pressure and state of every shroud pair over the face
    (axial z against radius r of the shroud_high node), from static_contact.csv."""
    rows = read_csv(os.path.join(result_dir, "static_contact.csv"))
    if not rows:
        return
    z = [1e3 * float(r["z_m"]) for r in rows]
    rad = [1e3 * math.hypot(float(r["x_m"]), float(r["y_m"])) for r in rows]
    p = [float(r["pressure_pa"]) / 1e6 for r in rows]
    fig, ax = plt.subplots(figsize=(10, 4.5))
    markers = {"open": "x", "stick": "o", "slip": "s"}
    sc = None
    for state, marker in markers.items():
        idx = [i for i, r in enumerate(rows) if r["state"] == state]
        if not idx:
            continue
        if state == "open":
            ax.scatter([z[i] for i in idx], [rad[i] for i in idx], c="0.5", marker=marker, s=30,
                       label=f"open ({len(idx)})")
        else:
            sc = ax.scatter([z[i] for i in idx], [rad[i] for i in idx], c=[p[i] for i in idx], cmap="viridis",
                            vmin=0.0, vmax=max(max(p), 1e-12), marker=marker, s=40, edgecolors="k",
                            linewidths=0.3, label=f"{state} ({len(idx)})")
    if sc is not None:
        fig.colorbar(sc, ax=ax, label="contact pressure [MPa]")
    total = sum(float(r["normal_load_n"]) for r in rows)
    ax.set_xlabel("axial position z [mm]")
    ax.set_ylabel("radius [mm]")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    ax.set_title("Static shroud contact: %d pairs, normal load %.4g N" % (len(rows), total))
    fig.tight_layout()
    fig.savefig(os.path.join(result_dir, "contact_static.png"), dpi=120)
    plt.close(fig)
