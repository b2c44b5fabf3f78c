#!/usr/bin/env python3
"""Jacobian error against the number of time samples N (the paper's Figure 17;
BENCHMARKS.md "Jacobian error against N").

For every N and normal preload, bench/forced/forced_pairs --jacobian-check traces the forced
response of the case (default: cases/paper_models_preload.toml, full3d, frame 0, 80-130 Hz,
5 pairs) and at every converged point evaluates the contact Jacobian both analytically and by
central differences of the same discrete map. Printed: the maximum over the curve (and the
median) of
  e_contact = ||D_a - D_fd||_F / ||D_a||_F        (the block-diagonal contact Jacobian dF/dW)
  e_full    = ||G (D_a - D_fd)||_F / ||I + G D_a||_F (the reduced Jacobian of the equations)

  python3 tools/bench_jacobian_error.py --build build-pairs
"""
import argparse
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build")
    ap.add_argument("--case", default=os.path.join(ROOT, "cases", "paper_models_preload.toml"))
    ap.add_argument("--samples", nargs="*", type=int, default=[64, 128, 256, 512, 1024, 2048])
    ap.add_argument("--preloads", nargs="*", type=float, default=[0.0, 0.25, 0.5])
    ap.add_argument("--set", action="append", default=[], help="extra KEY=VALUE overrides")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=3600.0)
    a = ap.parse_args()
    exe = os.path.join(a.build, "bench", "forced", "forced_pairs")
    if not os.path.exists(exe):
        sys.exit("no forced_pairs at %s (cmake --build %s --target forced_pairs)" % (exe, a.build))
    results = {}
    for n in a.samples:
        for p in a.preloads:
            cmd = [exe, a.case, "--jacobian-check", "--threads", str(a.threads),
                   "--set", "hbm.time_samples=%d" % n, "--set", "contact.normal_preload=%g" % p,
                   "--set", 'contact.model="full3d"', "--set", "contact.frame_angle_deg=0.0"]
            for s in a.set:
                cmd += ["--set", s]
            try:
                out = subprocess.run(cmd, capture_output=True, text=True, timeout=a.timeout).stdout
            except subprocess.TimeoutExpired:
                out = "status=timeout"
            kv = dict(tok.split("=", 1) for tok in out.split() if "=" in tok)
            results[(n, p)] = kv
            print("# N=%d preload=%g: %s" % (n, p, out.strip()), file=sys.stderr, flush=True)

    def fmt(kv, key):
        return "%.1e" % float(kv[key]) if key in kv else kv.get("status", "-")

    print("max over the curve of e_contact (e_full) [median e_contact] at the frequency of the max [Hz]; "
          "points with e_contact > 1e-6 / points")
    print()
    print("| N | " + " | ".join("preload %g N" % p for p in a.preloads) + " |")
    print("|---|" + "---|" * len(a.preloads))
    for n in a.samples:
        cells = []
        for p in a.preloads:
            kv = results[(n, p)]
            if "e_contact_max" not in kv:
                cells.append(kv.get("status", "-"))
                continue
            cells.append("%s (%s) [%s] at %.2f; %s/%s%s" % (
                fmt(kv, "e_contact_max"), fmt(kv, "e_full_max"), fmt(kv, "e_contact_median"),
                float(kv["e_contact_max_at_hz"]), kv.get("e_contact_points_above_1e-6", "?"), kv.get("points", "?"),
                "" if kv.get("status") == "reached_end" else ", " + kv.get("status", "?") + " at " + kv.get("points", "?") + " points"))
        print("| %d | %s |" % (n, " | ".join(cells)))


if __name__ == "__main__":
    main()
