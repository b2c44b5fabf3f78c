#!/usr/bin/python3
"""frf.png: nonlinear forced response against the free linear response; loops.png:
hysteresis loops of the contact pairs at the peak (from loops.csv)."""
import os

from plotting import read_csv, result_name



def plot_frf(result_dir):
    import matplotlib.pyplot as plt

    rows = read_csv(os.path.join(result_dir, "frf.csv"))
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
    stable = [r.get("stable", "") or "" for r in rows]
    drawn_unstable = False
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
        # Unstable stretches (frf.csv column `stable` = 0 at either end of a segment) dashed.
        seg_unstable = [stable[run[j]] == "0" or stable[run[j + 1]] == "0" for j in range(len(run) - 1)] or [False]
        start = 0
        for j in range(1, len(seg_unstable) + 1):
            if j == len(seg_unstable) or seg_unstable[j] != seg_unstable[start]:
                idx = run[start:j + 1]
                dashed = seg_unstable[start]
                label = None
                if first and start == 0:
                    label = "nonlinear (friction contact)" + (f", {len(runs)} pieces" if len(runs) > 1 else "")
                if dashed and not drawn_unstable:
                    label, drawn_unstable = "unstable (Hill)", True
                ax.semilogy([f[i] for i in idx], [a[i] for i in idx], color="C0", lw=1.5, ls="--" if dashed else "-",
                            label=label)
                start = j
        for c, k in enumerate(higher):
            ax.semilogy(fr, [max(float(rows[i][k]), 1e-30) for i in run], lw=0.7, ls="--", color=f"C{c + 1}",
                        label=(k[:-2] + (" (largest 6 of %d)" % (len(harmonics) - 2) if c == 0 and
                                         len(harmonics) - 2 > 6 else "")) if first else None)
    # The peak as run.json reports it: the largest of the located peaks (peaks.csv), or the
    # largest point when none was located (or the file is absent).
    pf, pa = max(zip(f, a), key=lambda p: p[1])
    peaks_csv = os.path.join(result_dir, "peaks.csv")
    if os.path.exists(peaks_csv):
        for r in read_csv(peaks_csv):
            if float(r["amplitude_m"]) >= pa:
                pf, pa = float(r["frequency_hz"]), float(r["amplitude_m"])
    ax.plot([pf], [pa], "o", color="C3", label=f"peak {pa:.4g} m at {pf:.6g} Hz")
    # Every located peak (peaks.csv), labelled with its frequency and amplitude.
    if os.path.exists(peaks_csv):
        for r in read_csv(peaks_csv):
            if r.get("located", "1") not in ("1", "true"):
                continue
            rf, ra = float(r["frequency_hz"]), float(r["amplitude_m"])
            ax.plot([rf], [ra], "v", color="C3", ms=5)
            ax.annotate(f"{rf:.6g} Hz\n{ra:.3g} m", (rf, ra), textcoords="offset points", xytext=(6, 6),
                        fontsize=7, color="C3")
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


def scale_unit(values, unit):
    """(factor, label): an SI prefix for `unit` that puts the largest |value| between 1 and 1000
    (the axes then read 12.5 um, not 0.0000125 m)."""
    big = max((abs(v) for v in values), default=0.0)
    for factor, prefix in ((1e-9, "n"), (1e-6, "\u00b5"), (1e-3, "m"), (1.0, ""), (1e3, "k"), (1e6, "M")):
        if big < 1000.0 * factor:
            return factor, prefix + unit
    return 1e6, "M" + unit


def main_direction(fx, fy):
    """Unit vector of the tangential force's main direction over the period: the principal
    axis of its samples (x for a 1D contact, whose y force is zero)."""
    n = len(fx)
    mx, my = sum(fx) / n, sum(fy) / n
    sxx = sum((a - mx) ** 2 for a in fx)
    syy = sum((b - my) ** 2 for b in fy)
    sxy = sum((a - mx) * (b - my) for a, b in zip(fx, fy))
    if sxx + syy == 0.0:
        return 1.0, 0.0
    import math
    angle = 0.5 * math.atan2(2.0 * sxy, sxx - syy)
    return math.cos(angle), math.sin(angle)


def plot_loops(result_dir):
    """loops.png: per pair, the tangential loop (force against displacement, both along the
    force's main direction), the orbit of the relative tangential motion, and the normal loop;
    displacements and forces in the SI prefix that fits them."""
    import matplotlib.pyplot as plt
    from matplotlib.ticker import ScalarFormatter

    rows = read_csv(os.path.join(result_dir, "loops.csv"))
    if not rows:
        return
    pairs = sorted({int(r["pair"]) for r in rows})
    shown = pairs[:8]
    col = {k: [float(r[k]) for r in rows] for k in ("x_m", "y_m", "z_m", "tx_n", "ty_n", "n_n")}
    du, dlabel = scale_unit(col["x_m"] + col["y_m"] + col["z_m"], "m")
    fu, flabel = scale_unit(col["tx_n"] + col["ty_n"] + col["n_n"], "N")
    fig, axes = plt.subplots(1, 3, figsize=(14, 4.4))
    for p in shown:
        sel = [r for r in rows if int(r["pair"]) == p]
        sel.append(sel[0])  # close the loop
        x = [float(r["x_m"]) for r in sel]
        y = [float(r["y_m"]) for r in sel]
        tx = [float(r["tx_n"]) for r in sel]
        ty = [float(r["ty_n"]) for r in sel]
        ex, ey = main_direction(tx[:-1], ty[:-1])
        u = [(a * ex + b * ey) / du for a, b in zip(x, y)]
        f = [(a * ex + b * ey) / fu for a, b in zip(tx, ty)]
        axes[0].plot(u, f, lw=1.2, label=f"pair {p}")
        axes[1].plot([a / du for a in x], [b / du for b in y], lw=1.2)
        axes[2].plot([float(r["z_m"]) / du for r in sel], [float(r["n_n"]) / fu for r in sel], lw=1.2)
    axes[0].set_title("tangential loop (along the force's main direction)")
    axes[0].set_xlabel(f"relative displacement [{dlabel}]")
    axes[0].set_ylabel(f"tangential force [{flabel}]")
    axes[1].set_title("relative tangential motion (orbit)")
    axes[1].set_xlabel(f"x [{dlabel}]")
    axes[1].set_ylabel(f"y [{dlabel}]")
    axes[1].set_aspect("equal", adjustable="datalim")
    if not any(col["n_n"]) and not any(col["z_m"]):
        axes[2].text(0.5, 0.5, "no normal motion or load in loops.csv\n(1d contact: constant normal load)",
                     ha="center", va="center", transform=axes[2].transAxes, fontsize=9, color="0.3")
    axes[2].set_title("normal loop")
    axes[2].set_xlabel(f"normal displacement (+ closes) [{dlabel}]")
    axes[2].set_ylabel(f"normal force (+ presses) [{flabel}]")
    for ax in axes:
        for axis in (ax.xaxis, ax.yaxis):
            fmt = ScalarFormatter(useOffset=False)
            fmt.set_scientific(False)
            axis.set_major_formatter(fmt)
        ax.locator_params(nbins=6)
        ax.grid(True, alpha=0.3)
    more = f" ({len(shown)} of {len(pairs)} pairs)" if len(shown) < len(pairs) else ""
    axes[0].legend(fontsize=7)
    fig.suptitle(f"{result_name(result_dir)}: contact loops at the peak{more}")
    fig.tight_layout()
    fig.savefig(os.path.join(result_dir, "loops.png"), dpi=110)
    plt.close(fig)
