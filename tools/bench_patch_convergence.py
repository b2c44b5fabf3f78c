#!/usr/bin/env python3
"""Mesh convergence of the forced-response peak with contact patches (BENCHMARKS.md
"Contact patches and mesh convergence"; docs/contact_patches.md).

Runs `shroudsim frf` on the default case for every mesh size and every contact.pairs value,
in both contact discretizations if asked, over a short range around the 101.6 Hz family,
and prints a Markdown table of the located peak amplitude (and its change from the next
coarser mesh), with the wall time of each run. Results stay in OUT/<size>_<pairs>_<disc>/
(a rerun with --reuse reads them instead of running again); OUT/convergence.csv holds every
row. --plot draws the peak against the element size.

  python3 tools/bench_patch_convergence.py --out /tmp/patch_conv
  python3 tools/bench_patch_convergence.py --sizes 0.018 0.0144 --pairs 5 all --disc patches nodes
"""
import argparse
import csv
import json
import os
import subprocess
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run(exe, case, sets, out, threads, timeout, reuse, no_run=False):
    if no_run and not os.path.exists(os.path.join(out, "run.json")):
        return {"status": "not run", "wall": 0.0}
    if not (reuse and os.path.exists(os.path.join(out, "run.json"))):
        cmd = [exe, "frf", case, "--quiet", "--threads", str(threads), "--out", out]
        for s in sets:
            cmd += ["--set", s]
        t0 = time.time()
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            return {"status": "timeout", "wall": time.time() - t0}
        wall = time.time() - t0
        with open(os.path.join(out, "wall.txt") if os.path.isdir(out) else os.devnull, "w") as f:
            f.write(f"{wall}\n")
        if proc.returncode != 0 and not os.path.exists(os.path.join(out, "run.json")):
            return {"status": f"exit {proc.returncode}: {proc.stderr.strip()[-200:]}", "wall": wall}
    try:
        with open(os.path.join(out, "run.json")) as f:
            j = json.load(f)
    except (OSError, ValueError) as e:
        return {"status": f"no run.json ({e})", "wall": 0.0}
    wall = 0.0
    try:
        with open(os.path.join(out, "wall.txt")) as f:
            wall = float(f.read())
    except (OSError, ValueError):
        pass
    frf = j.get("frf", {})
    model = j.get("frf_model", {})
    stages = j.get("stages", {})
    return {
        "status": j.get("status", "?"),
        "wall": wall,
        "peak": frf.get("peak_amplitude_m"),
        "peak_hz": frf.get("peak_frequency_hz"),
        "points": frf.get("points"),
        "pairs": model.get("contact_pairs"),
        "face_pairs": model.get("shroud_pairs_available"),
        "dofs": j.get("mesh", {}).get("dofs") or j.get("assembly", {}).get("dofs"),
        "frf_seconds": stages.get("frf") if isinstance(stages, dict) else None,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--exe", default=os.path.join(ROOT, "build", "src", "app", "shroudsim"))
    ap.add_argument("--case", default=os.path.join(ROOT, "cases", "shrouded_blade.toml"))
    ap.add_argument("--out", default="/tmp/shroudsim_patch_convergence")
    ap.add_argument("--sizes", type=float, nargs="+", default=[0.018, 0.0144, 0.0117, 0.0095, 0.0077])
    ap.add_argument("--pairs", nargs="+", default=["5", "10", "20", "all"])
    ap.add_argument("--disc", nargs="+", default=["patches"], choices=["patches", "nodes"])
    ap.add_argument("--range", type=float, nargs=2, default=[94.0, 108.0], help="frequency range [Hz]")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=7200.0)
    ap.add_argument("--reuse", action="store_true", help="read existing results instead of running again")
    ap.add_argument("--no-run", action="store_true", help="only read existing results (table and plot)")
    ap.add_argument("--plot", help="PNG: peak against element size")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    # A copy of the case in OUT: its mesh and mode caches live beside it, not in the repository.
    case = os.path.join(a.out, os.path.basename(a.case))
    with open(a.case) as src, open(case, "w") as dst:
        dst.write(src.read())
    rows = []
    for disc in a.disc:
        for pairs in a.pairs:
            for size in a.sizes:
                name = f"{size:g}_{pairs}_{disc}"
                out = os.path.join(a.out, name)
                os.makedirs(out, exist_ok=True)
                pv = f'"{pairs}"' if pairs == "all" else pairs
                sets = [f"geometry.mesh_size={size!r}", f"contact.pairs={pv}", f'contact.discretization="{disc}"',
                        f"continuation.frequency_start_hz={a.range[0]!r}", f"continuation.frequency_end_hz={a.range[1]!r}"]
                r = run(a.exe, case, sets, out, a.threads, a.timeout, a.reuse or a.no_run, a.no_run)
                r.update({"size": size, "pairs_key": pairs, "disc": disc})
                rows.append(r)
                print(f"{name}: {r['status']} peak {r.get('peak')} at {r.get('peak_hz')} Hz, {r['wall']:.1f} s", flush=True)
    with open(os.path.join(a.out, "convergence.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["discretization", "pairs", "mesh_size_m", "contact_elements", "face_pairs", "status", "peak_m",
                    "peak_hz", "change_from_coarser", "wall_s"])
        prev = {}
        for r in rows:
            key = (r["disc"], r["pairs_key"])
            ch = ""
            if r.get("peak") and prev.get(key):
                ch = f"{r['peak'] / prev[key] - 1:.4f}"
            prev[key] = r.get("peak")
            w.writerow([r["disc"], r["pairs_key"], r["size"], r.get("pairs"), r.get("face_pairs"), r["status"],
                        r.get("peak"), r.get("peak_hz"), ch, f"{r['wall']:.1f}"])
    # Markdown table: one row per (discretization, pairs), one column per size.
    print()
    print("| discretization | pairs | " + " | ".join(f"{s:g}" for s in a.sizes) + " |")
    print("| --- | --- | " + " | ".join("---" for _ in a.sizes) + " |")
    for disc in a.disc:
        for pairs in a.pairs:
            cells = []
            for size in a.sizes:
                r = next(x for x in rows if x["disc"] == disc and x["pairs_key"] == pairs and x["size"] == size)
                if r.get("peak"):
                    cells.append(f"{r['peak']:.4e} ({r['wall']:.0f} s)")
                else:
                    cells.append(r["status"][:30])
            print(f"| {disc} | {pairs} | " + " | ".join(cells) + " |")
    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(7, 4.5))
        for disc in a.disc:
            for pairs in a.pairs:
                xs = [r["size"] * 1e3 for r in rows if r["disc"] == disc and r["pairs_key"] == pairs and r.get("peak")]
                ys = [r["peak"] * 1e6 for r in rows if r["disc"] == disc and r["pairs_key"] == pairs and r.get("peak")]
                if xs:
                    ax.plot(xs, ys, "o-" if disc == "patches" else "s--", label=f"{disc}, pairs = {pairs}")
        ax.set_xlabel("geometry.mesh_size [mm]")
        ax.set_ylabel("peak amplitude [µm]")
        ax.invert_xaxis()
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
        ax.set_title("Forced-response peak (101.6 Hz family) under mesh refinement")
        fig.tight_layout()
        fig.savefig(a.plot, dpi=120)
        print(f"plot: {a.plot}")


if __name__ == "__main__":
    main()
