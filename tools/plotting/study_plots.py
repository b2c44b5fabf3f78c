#!/usr/bin/python3
"""study.png: peak amplitude (and its frequency) against the first varied key, one line per
combination of the other keys; for a sampled study, the peak amplitude's distribution and its
dependence on each uncertain input."""
import csv
import os

from plotting import result_name


def plot_sampled(result_dir, rows):
    """A sampled study (first column `sample`): the histogram of the peak amplitude with its
    5/50/95 % percentiles (and the threshold's exceedance, study_statistics.json), and the peak
    amplitude against each uncertain input with Spearman's rank correlation."""
    import json

    import matplotlib.pyplot as plt

    fixed = ["sample", "status", "peak_amplitude_m", "peak_frequency_hz", "points", "seconds", "folder", "message",
             "harmonics", "time_samples"]
    inputs = [k for k in rows[0] if k not in fixed]
    ok = [r for r in rows if r["status"] == "ok"]
    if not ok:
        return
    peaks = sorted(float(r["peak_amplitude_m"]) for r in ok)
    study = {}
    stats_json = os.path.join(result_dir, "study_statistics.json")
    if os.path.exists(stats_json):
        with open(stats_json) as f:
            study = json.load(f)
    fig, axes = plt.subplots(1, 1 + len(inputs), figsize=(4.5 * (1 + len(inputs)), 4.2))
    ax = axes[0]
    ax.hist(peaks, bins=max(5, min(40, len(peaks) // 5)), color="C0", alpha=0.8)
    stats = study.get("statistics", {}).get("peak_amplitude_m", {})
    for key, style in (("p05", ":"), ("p50", "-"), ("p95", ":")):
        if key in stats:
            ax.axvline(stats[key], color="k", ls=style, lw=1, label=f"{int(key[1:])} %: {stats[key]:.4g} m")
    exc = study.get("exceedance")
    if exc:
        ax.axvline(exc["threshold_m"], color="C3", lw=1.5,
                   label=f"P(> {exc['threshold_m']:.3g} m) = {exc['probability']:.3f} "
                         f"[{exc['low_95']:.3f}, {exc['high_95']:.3f}]")
    ax.set_xlabel("peak amplitude [m]")
    ax.set_ylabel("samples")
    ax.set_title(f"{result_name(result_dir)}: {len(ok)} of {len(rows)} samples", fontsize=9)
    ax.legend(fontsize=7)
    rho = {s["key"]: s.get("spearman_peak_amplitude") for s in study.get("sensitivity", [])}
    for bx, key in zip(axes[1:], inputs):
        bx.plot([float(r[key]) for r in ok], [float(r["peak_amplitude_m"]) for r in ok], "o", ms=3)
        failed = [r for r in rows if r["status"] != "ok"]
        for r in failed:
            bx.axvline(float(r[key]), color="C3", lw=0.5, alpha=0.5)
        r_text = f", Spearman {rho[key]:+.2f}" if rho.get(key) is not None else ""
        bx.set_title(f"{key}{r_text}", fontsize=9)
        bx.set_xlabel(key)
        bx.set_ylabel("peak amplitude [m]")
    for a in axes:
        a.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(result_dir, "study.png"), dpi=110)
    plt.close(fig)


def plot_study(result_dir):
    import matplotlib.pyplot as plt

    with open(os.path.join(result_dir, "study.csv"), newline="") as f:
        rows = [r for r in csv.DictReader(f)]
    if not rows:
        return
    if next(iter(rows[0])) == "sample":
        plot_sampled(result_dir, rows)
        return
    fixed = ["status", "peak_amplitude_m", "peak_frequency_hz", "points", "seconds", "folder", "harmonics",
             "time_samples"]
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
    ax.set_title(result_name(result_dir))
    fig.tight_layout()
    fig.savefig(os.path.join(result_dir, "study.png"), dpi=110)
    plt.close(fig)


def plot_trade(result_dir):
    """trade.png (`study --convergence`): error against wall time, one marker series per knob,
    each point labelled with its value; the references (error 0) are listed in the legend,
    not drawn. The lower-left hull is the Pareto front: nothing is both cheaper and better."""
    import matplotlib.pyplot as plt

    with open(os.path.join(result_dir, "trade.csv"), newline="") as f:
        rows = [r for r in csv.DictReader(f) if r["status"] == "ok" and r["peaks_error"] != ""]
    if not rows:
        return
    def cost(r):  # CPU time of the run's thread where recorded (load-independent), else wall time
        return float(r.get("cpu_seconds") or r["seconds"])

    knobs = []
    for r in rows:
        if r["knob"] not in knobs:
            knobs.append(r["knob"])
    fig, ax = plt.subplots(figsize=(12, 6))
    floor = min([float(r["peaks_error"]) for r in rows if float(r["peaks_error"]) > 0] or [1e-12]) / 3
    pts = []
    markers = "osD^v<>ph*"
    for i, k in enumerate(knobs):
        sel = [r for r in rows if r["knob"] == k]
        ref = next((r for r in sel if float(r["peaks_error"]) == 0), None)
        xs = [cost(r) for r in sel if float(r["peaks_error"]) > 0]
        ys = [float(r["peaks_error"]) for r in sel if float(r["peaks_error"]) > 0]
        label = k + (f" (reference {ref['value']}: {cost(ref):.3g} s)" if ref else "")
        ax.loglog(xs, ys, markers[i % len(markers)], ls="-", lw=0.8, label=label)
        for r in sel:
            if float(r["peaks_error"]) > 0:
                ax.annotate(r["value"], (cost(r), float(r["peaks_error"])), fontsize=7,
                            textcoords="offset points", xytext=(4, 3))
                pts.append((cost(r), float(r["peaks_error"])))
    pts.sort()
    front, best = [], float("inf")
    for x, y in pts:
        if y < best:
            front.append((x, y))
            best = y
    if len(front) > 1:
        ax.step([p[0] for p in front], [p[1] for p in front], where="post", color="0.5", lw=0.8, ls=":",
                label="Pareto front")
    ax.set_ylim(bottom=floor)
    ax.set_xlabel("CPU time of the run [s]")
    ax.set_ylabel("largest relative change of a resonance peak vs the knob's reference")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    ax.set_title(result_name(result_dir) + ": accuracy against cost, one knob at a time")
    fig.tight_layout()
    fig.savefig(os.path.join(result_dir, "trade.png"), dpi=110)
    plt.close(fig)
