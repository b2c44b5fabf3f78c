#!/usr/bin/env python3
"""Forced-response cost against the number of contact pairs, analytic against
finite-difference Jacobian (the paper's Example 4; BENCHMARKS.md "Many contact pairs").

Runs `shroudsim frf` on the default case with `--set` overrides for every pair count and
both Jacobians, reads run.json (the "frf" stage wall time, points, Newton iterations) and
prints a Markdown table; with --breakdown it also runs bench/forced/forced_pairs on the same
settings (analytic) for where the time goes (contact evaluation, linear solves). --plot
draws time against pairs.

The finite-difference runs at many pairs are slow, so every run is capped to the same short
frequency range around the 101.6 Hz family (--range, default 96 to 104 Hz): both Jacobians
do the same work, and the time per Newton iteration is given as well.

  python3 tools/bench_pairs.py --build build-pairs --plot bench_pairs.png
  python3 tools/bench_pairs.py --pairs 1 2 5 --fine-pairs   # quick: default mesh only
"""
import argparse
import json
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run_frf(exe, case, sets, out, threads, timeout, reuse=False):
    cmd = [exe, "frf", case, "--quiet", "--threads", str(threads), "--out", out]
    for s in sets:
        cmd += ["--set", s]
    t0 = time.time()
    rc = 0
    if not (reuse and os.path.exists(os.path.join(out, "run.json"))):
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
            rc = proc.returncode
        except subprocess.TimeoutExpired:
            return {"status": "timeout", "wall": time.time() - t0}
    wall = time.time() - t0
    try:
        with open(os.path.join(out, "run.json")) as f:
            j = json.load(f)
    except (OSError, ValueError):
        return {"status": "rc=%d" % rc, "wall": wall}
    stages = {s["name"]: s["seconds"] for s in j.get("stages", [])}
    frf = j.get("frf", {})
    # The "frf" stage includes building the model (mesh, assembly and modes when not cached,
    # K_h factors and receptances), each also reported as its own stage: the forced response
    # proper is frf minus those.
    inner = sum(v for k, v in stages.items() if k != "frf")
    return {
        "status": frf.get("status", "rc=%d" % rc),
        "wall": wall,
        "frf_s": stages.get("frf", float("nan")) - inner,
        "receptances_s": stages.get("receptances", 0.0),
        "points": frf.get("points", 0),
        "newton": frf.get("newton_iterations", 0),
        "evaluations": frf.get("residual_evaluations", 0),
        "unknowns": frf.get("unknowns", 0),
        "pairs": frf.get("contact_pairs", 0),
        "available": j.get("frf_model", {}).get("shroud_pairs_available", 0),
        "peak": frf.get("peak_amplitude_m", float("nan")),
    }


def run_breakdown(exe, case, sets, threads, timeout):
    cmd = [exe, case, "--threads", str(threads)]
    for s in sets:
        cmd += ["--set", s]
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {}
    out = {}
    for tok in proc.stdout.split():
        if "=" in tok:
            k, v = tok.split("=", 1)
            try:
                out[k] = float(v)
            except ValueError:
                out[k] = v
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build", help="build directory (default: build)")
    ap.add_argument("--case", default=os.path.join(ROOT, "cases", "shrouded_blade.toml"))
    ap.add_argument("--pairs", nargs="*", default=["1", "2", "5", "10", "20", "all"],
                    help="pair counts on the case's mesh ('all' = every matched pair)")
    ap.add_argument("--fine-mesh-size", type=float, default=0.0075,
                    help="mesh_size of the finer mesh for the larger pair counts (109 pairs at 0.0075)")
    ap.add_argument("--fine-pairs", nargs="*", default=["50", "100"], help="pair counts on the finer mesh")
    ap.add_argument("--range", nargs=2, type=float, default=[96.0, 104.0], metavar=("F0", "F1"),
                    help="frequency range [Hz] of every run (default 96 104)")
    ap.add_argument("--initial-step", type=float, default=0.25)
    ap.add_argument("--jacobians", nargs="*", default=["analytic", "finite_difference"])
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=3600.0, help="seconds per run")
    ap.add_argument("--work", default="/tmp/shroudsim_bench_pairs", help="result folders")
    ap.add_argument("--breakdown", action="store_true", help="also run forced_pairs (analytic) for the cost split")
    ap.add_argument("--plot", help="write a PNG of time against pairs")
    ap.add_argument("--json", help="write all results as JSON")
    ap.add_argument("--reuse", action="store_true", help="read the run.json of runs already in --work instead of rerunning")
    a = ap.parse_args()

    exe = os.path.join(a.build, "src", "app", "shroudsim")
    bench = os.path.join(a.build, "bench", "forced", "forced_pairs")
    if not os.path.exists(exe):
        sys.exit("no shroudsim at %s (build it, or pass --build)" % exe)
    configs = [(None, p) for p in a.pairs] + [(a.fine_mesh_size, p) for p in a.fine_pairs]
    rows = []
    for mesh_size, pairs in configs:
        sets = [
            "continuation.frequency_start_hz=%g" % a.range[0],
            "continuation.frequency_end_hz=%g" % a.range[1],
            "continuation.initial_step=%g" % a.initial_step,
            'contact.pairs="all"' if pairs == "all" else "contact.pairs=%s" % pairs,
        ]
        tag = "default"
        if mesh_size is not None:
            tag = "ms%g" % mesh_size
            sets += ["geometry.mesh_size=%g" % mesh_size, 'name="bench_pairs_%s"' % tag]
        row = {"mesh": tag, "pairs_asked": pairs}
        for jac in a.jacobians:
            out = os.path.join(a.work, "%s_p%s_%s" % (tag, pairs, jac))
            r = run_frf(exe, a.case, sets + ['hbm.jacobian="%s"' % jac], out, a.threads, a.timeout, a.reuse)
            row[jac] = r
            print("# %s pairs=%s %s: %s" % (tag, pairs, jac, json.dumps(r)), file=sys.stderr, flush=True)
        if a.breakdown and os.path.exists(bench) and not a.reuse:
            row["breakdown"] = run_breakdown(bench, a.case, sets, a.threads, a.timeout)
            print("# breakdown: %s" % json.dumps(row["breakdown"]), file=sys.stderr, flush=True)
        rows.append(row)

    def done(r):
        return bool(r) and r.get("newton", 0) > 0

    def cell(r, key, fmt):
        if not done(r):
            return (r or {}).get("status", "-")
        # A run that did not reach the end of the range (the continuation stopped; the time
        # is that of the work done) is marked with its status.
        return fmt % r[key] + ("" if r["status"] == "reached_end" else " (%s)" % r["status"])

    print("frequency range %g-%g Hz, initial step %g, %d threads; times = `frf` stage of run.json minus the model stages inside it (mesh, assembly, modes, receptances) [s]" %
          (a.range[0], a.range[1], a.initial_step, a.threads))
    print()
    print("| mesh | pairs | unknowns | analytic [s] | points / Newton | s per Newton | FD [s] | points / Newton | s per Newton | FD / analytic (time) | (per Newton) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for row in rows:
        an, fd = row.get("analytic"), row.get("finite_difference")
        ref = an or fd or {}
        cols = [row["mesh"], str(ref.get("pairs", row["pairs_asked"])), str(ref.get("unknowns", "-"))]
        for r in (an, fd):
            ok = done(r)
            cols += [cell(r, "frf_s", "%.1f"), "%d / %d" % (r["points"], r["newton"]) if ok else "-",
                     "%.3f" % (r["frf_s"] / r["newton"]) if ok else "-"]
        both = done(an) and done(fd)
        cols += ["%.1f" % (fd["frf_s"] / an["frf_s"]) if both else "-",
                 "%.1f" % ((fd["frf_s"] / fd["newton"]) / (an["frf_s"] / an["newton"])) if both else "-"]
        print("| " + " | ".join(cols) + " |")
    if a.breakdown:
        print()
        print("| mesh | pairs | Jacobian evaluations | contact [s] | contact per Jacobian evaluation [ms] | per pair [ms] | linear solves [s] | G D [s] | receptances [s] | LU / GMRES solves (iterations) |")
        print("|---|---|---|---|---|---|---|---|---|---|")
        for row in rows:
            b = row.get("breakdown") or {}
            if not b:
                continue
            je = max(b.get("jacobian_evaluations", 1), 1)
            per = 1e3 * b["contact_s"] / je
            print("| %s | %d | %d | %.1f | %.2f | %.3f | %.1f | %.1f | %.1f | %d / %d (%d) |" % (
                row["mesh"], b["pairs"], je, b["contact_s"], per, per / b["pairs"], b["solve_s"], b["jacobian_s"],
                b["receptance_s"], b["factorizations"], b["krylov_solves"], b["krylov_iterations"]))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(rows, f, indent=1)
    if a.plot:
        try:
            import matplotlib
            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
        except ImportError:
            print("matplotlib not installed: no plot", file=sys.stderr)
            return
        fig, ax = plt.subplots(figsize=(6, 4))
        for jac, style in (("analytic", "o-"), ("finite_difference", "s--")):
            pts = [(row[jac]["pairs"], row[jac]["frf_s"] / row[jac]["newton"]) for row in rows if done(row.get(jac))]
            if pts:
                ax.loglog(*zip(*pts), style, label=jac.replace("_", " "))
        ax.set_xlabel("contact pairs")
        ax.set_ylabel("wall time per Newton iteration [s]")
        ax.set_title("%g-%g Hz, H = 5, N = 512" % tuple(a.range))
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(a.plot, dpi=120)


if __name__ == "__main__":
    main()
