#!/usr/bin/python3
"""nlmodes.png: the nonlinear mode's frequency and damping ratio against the modal amplitude
(log axis), from nlmodes.csv; with nlmodes_synthesis.csv, the forced responses synthesized
from the mode at each excitation level (a third panel)."""
import os

from plotting import read_csv, result_name



def plot_nlmodes(result_dir):
    import matplotlib.pyplot as plt

    rows = read_csv(os.path.join(result_dir, "nlmodes.csv"))
    if not rows:
        return
    a = [float(r["amplitude"]) for r in rows]
    f = [float(r["frequency_hz"]) for r in rows]
    d = [float(r["damping_ratio"]) for r in rows]
    dc = [float(r["contact_damping_ratio"]) for r in rows]
    syn_path = os.path.join(result_dir, "nlmodes_synthesis.csv")
    syn = read_csv(syn_path) if os.path.exists(syn_path) else []
    panels = 3 if syn else 2
    fig, axes = plt.subplots(panels, 1, figsize=(8, 3.2 * panels))
    ax = axes[0]
    ax.semilogx(a, f, color="C0", lw=1.5)
    ax.set_ylabel("frequency [Hz]")
    ax.set_xlabel("modal amplitude a [m kg^0.5]")
    ax.grid(True, which="both", alpha=0.3)
    ax.set_title(result_name(result_dir) + ": nonlinear mode (EPMC)")
    ax = axes[1]
    ax.semilogx(a, d, color="C1", lw=1.5, label="modal damping ratio D")
    ax.semilogx(a, dc, color="C2", lw=1, ls="--", label="contacts' share")
    ax.set_ylabel("damping ratio [-]")
    ax.set_xlabel("modal amplitude a [m kg^0.5]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    if syn:
        ax = axes[2]
        scales = []
        for r in syn:
            if r["scale"] not in scales:
                scales.append(r["scale"])
        for c, s in enumerate(scales):
            pts = [r for r in syn if r["scale"] == s]
            ax.semilogy([float(r["frequency_hz"]) for r in pts], [float(r["amplitude_m"]) for r in pts],
                        color=f"C{c}", lw=1.2, label=f"excitation x {float(s):g}")
        ax.plot(f, [float(r["response_per_amplitude"]) * x for r, x in zip(rows, a)], color="0.5", lw=0.8,
                ls=":", label="backbone")
        # Near the mode: the synthesis means nothing far from its backbone.
        ax.set_xlim(0.7 * min(f), 1.3 * max(f))
        ax.set_xlabel("excitation frequency [Hz]")
        ax.set_ylabel("response max_t |u(t)| [m]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        ax.set_title("forced response synthesized from the mode")
    fig.tight_layout()
    fig.savefig(os.path.join(result_dir, "nlmodes.png"), dpi=110)
    plt.close(fig)
