#!/usr/bin/env python3
"""Scaling of `shroudsim study` over MPI ranks: one sampled study of the default case (the
friction coefficient uniform on [0.2, 0.4] and the interference normal 10 +- 2.5 um, Latin
hypercube, N = 256; 64 samples by default) run with `mpirun -n K` for each K in --ranks
(one worker thread per rank; K above the cores is oversubscribed: the table says so), and,
with --threads-too, once without mpirun on as many threads as cores for comparison.

Prints a Markdown table: wall time, speed-up and parallel efficiency against one rank, the
summed and largest per-point CPU time (study.csv `seconds` is wall time per point; run.json
of each point has its CPU time), and whether every run's table equals the first one's (every
column but the point wall times). The mode cache of cases/.cache is filled by a first run of
the case (not timed), so every timed run reads the same modes.

  /usr/bin/python3 tools/bench_study_ranks.py --build build --samples 64 --ranks 1 2 4
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SAMPLE = ('{ "contact.friction_coefficient" = { distribution = "uniform", min = 0.2, max = 0.4 }, '
          '"contact.interference" = { distribution = "normal", mean = 1.0e-5, std = 2.5e-6 } }')


def table(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    drop = rows[0].index("seconds")
    return [[c for i, c in enumerate(r) if i != drop] for r in rows]


def point_cpu(out):
    total, largest = 0.0, 0.0
    for name in sorted(os.listdir(out)):
        rj = os.path.join(out, name, "run.json")
        if os.path.isfile(rj):
            with open(rj) as f:
                c = json.load(f).get("point_cpu_seconds", 0.0)
            total += c
            largest = max(largest, c)
    return total, largest


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--samples", type=int, default=64)
    ap.add_argument("--ranks", type=int, nargs="+", default=[1, 2, 4])
    ap.add_argument("--threads-too", action="store_true", help="also one run on threads only (no mpirun)")
    ap.add_argument("--work", default="/tmp/shroudsim_bench_ranks")
    args = ap.parse_args()
    exe = os.path.join(args.build, "src", "app", "shroudsim")
    case = os.path.join(ROOT, "cases", "shrouded_wheel.toml")
    sets = ["hbm.time_samples=256", "study.sample=" + SAMPLE, "study.samples=%d" % args.samples]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OMPI_MCA_btl_vader_single_copy_mechanism="none")
    cores = os.cpu_count() or 1
    os.makedirs(args.work, exist_ok=True)
    # Fill the mesh and mode caches (not timed).
    subprocess.run([exe, "frf", case, "-q", "--set", "hbm.time_samples=256", "--out",
                    os.path.join(args.work, "warm")], check=True, env=env)
    runs = [("mpirun -n %d" % k, k, ["mpirun", "--oversubscribe", "-n", str(k), exe]) for k in args.ranks]
    if args.threads_too:
        runs.append(("threads %d" % cores, 0, [exe]))
    results = []
    for label, ranks, launcher in runs:
        out = os.path.join(args.work, label.replace(" ", "_"))
        cmd = launcher + ["study", case, "-q", "--out", out, "--threads", "1" if ranks else str(cores)]
        for s in sets:
            cmd += ["--set", s]
        t0 = time.time()
        proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
        wall = time.time() - t0
        if proc.returncode not in (0, 3):
            sys.exit("%s failed (%d):\n%s" % (label, proc.returncode, proc.stderr[-2000:]))
        with open(os.path.join(out, "run.json")) as f:
            st = json.load(f)["study"]
        total, largest = point_cpu(out)
        results.append(dict(label=label, ranks=ranks, wall=wall, workers=st["workers"], failed=st["failed"],
                            cpu=total, largest=largest, table=table(os.path.join(out, "study.csv"))))
        print("%s: %.1f s" % (label, wall), file=sys.stderr)
    base = results[0]
    print("| run | workers | wall (s) | speed-up | efficiency | point CPU sum (s) | largest point (s) | failed | table as first |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for r in results:
        n = r["workers"]
        over = " (oversubscribed)" if r["ranks"] > cores else ""
        speed = base["wall"] / r["wall"]
        print("| %s%s | %d | %.1f | %.2f | %.0f %% | %.0f | %.1f | %d | %s |" % (
            r["label"], over, n, r["wall"], speed, 100.0 * speed / min(n, cores) * (base["workers"]),
            r["cpu"], r["largest"], r["failed"], "yes" if r["table"] == base["table"] else "NO"))
    print("\n%d samples, %d cores; efficiency = speed-up / min(workers, cores)." % (args.samples, cores))


if __name__ == "__main__":
    main()
