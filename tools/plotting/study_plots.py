#!/usr/bin/python3
"""study.png: peak amplitude (and its frequency) against the first varied key, one line per
combination of the other keys."""
import csv
import os


def plot_study(result_dir):
    import matplotlib.pyplot as plt

    with open(os.path.join(result_dir, "study.csv"), newline="") as f:
        rows = [r for r in csv.DictReader(f)]
    if not rows:
        return
    fixed = ["status", "peak_amplitude_m", "peak_frequency_hz", "points", "seconds", "folder"]
    keys = [k for k in rows[0] if k not in fixed]
    first, others = keys[0], keys[1:]

    def num(v):
        try:
            return float(v)
        except ValueError:
            return None

    numeric = all(num(r[first]) is not None for r in rows)
    groups = {}
    for r in rows:
        groups.setdefault(tuple(r[k] for k in others), []).append(r)
    fig, (ax, bx) = plt.subplots(2, 1, figsize=(8, 7), sharex=True)
    for label, rs in groups.items():
        ok = [r for r in rs if r["status"] == "ok"]
        xs = [num(r[first]) if numeric else r[first] for r in ok]
        name = ", ".join(f"{k}={v}" for k, v in zip(others, label)) or None
        ax.plot(xs, [float(r["peak_amplitude_m"]) for r in ok], "o-", label=name)
        bx.plot(xs, [float(r["peak_frequency_hz"]) for r in ok], "o-", label=name)
    ax.set_ylabel("peak amplitude [m]")
    ax.set_yscale("log")
    bx.set_ylabel("peak frequency [Hz]")
    bx.set_xlabel(first)
    for a in (ax, bx):
        a.grid(True, which="both", alpha=0.3)
    if others:
        ax.legend(fontsize=7)
    ax.set_title(os.path.basename(os.path.normpath(result_dir)))
    fig.tight_layout()
    fig.savefig(os.path.join(result_dir, "study.png"), dpi=110)
    plt.close(fig)
