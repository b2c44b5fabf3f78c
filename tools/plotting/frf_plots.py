#!/usr/bin/python3
"""frf.png: nonlinear forced response against the free linear response; loops.png:
hysteresis loops of the contact pairs at the peak (from loops.csv)."""
import csv
import os

from plotting import result_name


def _read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return rows


def plot_frf(result_dir):
    import matplotlib.pyplot as plt

    rows = _read_csv(os.path.join(result_dir, "frf.csv"))
    if not rows:
        return
    f = [float(r["frequency_hz"]) for r in rows]
    a = [float(r["amplitude_m"]) for r in rows]
    lin = [float(r["linear_amplitude_m"]) for r in rows]
    # A curve traced in two pieces (forward, then back from the end: column `piece`) is drawn
    # piece by piece, so that no line joins the end of one to the start of the other.
    piece = [int(r.get("piece", 0) or 0) for r in rows]
    runs = []
    for i, p in enumerate(piece):
        if i == 0 or p != piece[i - 1]:
            runs.append([])
        runs[-1].append(i)
    fig, ax = plt.subplots(figsize=(8, 5))
    harmonics = [k for k in rows[0] if k.startswith("h") and k.endswith("_m")]
    # h0 is the static part, h1 dominates: the higher ones, at most the 6 largest (H can be
    # 200: a line and a legend entry each would bury the curve).
    higher = harmonics[2:]
    if len(higher) > 6:
        higher = sorted(higher, key=lambda k: -max(float(r[k]) for r in rows))[:6]
        higher.sort(key=lambda k: int(k[1:-2]))
    for n, run in enumerate(runs):
        fr = [f[i] for i in run]
        first = n == 0
        ax.semilogy(fr, [lin[i] for i in run], color="0.6", lw=1, label="linear, contact open" if first else None)
        ax.semilogy(fr, [a[i] for i in run], color="C0", lw=1.5,
                    label=("nonlinear (friction contact)" + (f", {len(runs)} pieces" if len(runs) > 1 else "")) if first else None)
        for c, k in enumerate(higher):
            ax.semilogy(fr, [max(float(rows[i][k]), 1e-30) for i in run], lw=0.7, ls="--", color=f"C{c + 1}",
                        label=(k[:-2] + (" (largest 6 of %d)" % (len(harmonics) - 2) if c == 0 and
                                         len(harmonics) - 2 > 6 else "")) if first else None)
    # The peak as run.json reports it: the largest of the located peaks (peaks.csv), or the
    # largest point when none was located (or the file is absent).
    pf, pa = max(zip(f, a), key=lambda p: p[1])
    peaks_csv = os.path.join(result_dir, "peaks.csv")
    if os.path.exists(peaks_csv):
        for r in _read_csv(peaks_csv):
            if float(r["amplitude_m"]) >= pa:
                pf, pa = float(r["frequency_hz"]), float(r["amplitude_m"])
    ax.plot([pf], [pa], "o", color="C3", label=f"peak {pa:.4g} m at {pf:.3f} Hz")
    ax.set_xlabel("excitation frequency [Hz]")
    ax.set_ylabel("response amplitude max_t |u(t)| [m]")
    ax.set_ylim(bottom=max(min(a) * 1e-3, 1e-14))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(result_name(result_dir))
    fig.tight_layout()
    fig.savefig(os.path.join(result_dir, "frf.png"), dpi=110)
    plt.close(fig)

    loops = os.path.join(result_dir, "loops.csv")
    if os.path.exists(loops):
        plot_loops(result_dir)


def plot_loops(result_dir):
    import matplotlib.pyplot as plt

    rows = _read_csv(os.path.join(result_dir, "loops.csv"))
    pairs = sorted({int(r["pair"]) for r in rows})
    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    for p in pairs:
        sel = [r for r in rows if int(r["pair"]) == p]
        sel.append(sel[0])  # close the loop
        for ax, (x, y) in zip(axes, [("x_m", "tx_n"), ("y_m", "ty_n"), ("z_m", "n_n")]):
            ax.plot([float(r[x]) for r in sel], [float(r[y]) for r in sel], lw=1, label=f"pair {p}")
    for ax, t in zip(axes, ["tangential x", "tangential y", "normal"]):
        ax.set_title(t)
        ax.set_xlabel("relative displacement [m]")
        ax.grid(True, alpha=0.3)
    axes[0].set_ylabel("contact force [N]")
    axes[0].legend(fontsize=7)
    fig.suptitle("contact loops at the peak")
    fig.tight_layout()
    fig.savefig(os.path.join(result_dir, "loops.png"), dpi=110)
    plt.close(fig)
