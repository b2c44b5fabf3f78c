#!/usr/bin/env python3
"""Fuzz test of the command line (docs/contract.md): mutated case files and meshes.

usage: fuzz_inputs.py SHROUDSIM_EXE [--cases N] [--meshes N] [--seed S] [--keep DIR]

Every run must end in exit 0, 2 or 3 within TIMEOUT seconds; exit 0 or 3 leaves a results
folder whose run.json status matches (ok / numerics_failed) and whose CSV and JSON files
hold no NaN or infinity; exit 2 leaves no results folder; no staging folder survives a
run. Mutations of a small lumped case (fast) and of a coarse generated sector mesh (read
by `mesh`): lines deleted, duplicated or truncated, values replaced by hostile tokens
(nan, inf, huge, negative, zero, wrong types, empty arrays and tables), bytes inserted.
Seeded: a failure prints its seed, case number and the mutated file, and --keep keeps it.
Pure Python, no numpy.
"""
import argparse
import json
import math
import os
import random
import shutil
import subprocess
import sys
import tempfile

TIMEOUT = 60.0  # seconds per run: the slowest legitimate run here takes ~2 s

LUMPED = """name = "fz"
[structure]
type = "lumped"
mass = [[1.0, 0.0], [0.0, 1.0]]
stiffness = [[2000.0, -1000.0], [-1000.0, 2000.0]]
damping = [[0.4, -0.2], [-0.2, 0.4]]
[excitation]
force = 1.0
dof = 0
[response]
dof = 1
[contact]
model = "1d"
normal_preload = 1.0
friction_coefficient = 0.3
tangential_stiffness = 1000.0
normal_stiffness = 1000.0
[[contact.elements]]
x_dof = 1
[hbm]
harmonics = 3
time_samples = 64
[continuation]
frequency_start_hz = 3.0
frequency_end_hz = 12.0
max_points = 400
"""

SECTOR = """name = "fzmesh"
[structure]
mesh = "m.msh"
sectors = 8
[modal]
modes = 4
harmonic_indices = [0]
"""

TOKENS = ["nan", "inf", "-inf", "1e308", "-1e308", "0", "-1", "1e-300", "0.0", "-0.5", "3",
          "100000000", '"x"', '""', "true", "[]", "[1, 2]", "[[1.0]]", "{}", "{ a = 1 }",
          '"auto"', '"all"', "2.5", "-3"]


def mutate_text(text, rng):
    lines = text.split("\n")
    kind = rng.randrange(7)
    if kind == 0 and len(lines) > 1:  # delete a line
        del lines[rng.randrange(len(lines))]
    elif kind == 1:  # duplicate a line (a duplicate key, or a repeated table)
        i = rng.randrange(len(lines))
        lines.insert(i, lines[i])
    elif kind == 2:  # truncate
        return text[: rng.randrange(len(text))]
    elif kind == 3:  # insert random bytes
        i = rng.randrange(len(text))
        junk = "".join(chr(rng.choice([0, 7, 9, 10, 13, 34, 39, 61, 91, 93, 123, 125, 0xe9, 0x2028]))
                       for _ in range(rng.randrange(1, 6)))
        return text[:i] + junk + text[i:]
    else:  # replace a value by a hostile token
        candidates = [i for i, l in enumerate(lines) if "=" in l]
        if candidates:
            i = rng.choice(candidates)
            key = lines[i].split("=", 1)[0]
            lines[i] = key + "= " + rng.choice(TOKENS)
    return "\n".join(lines)


def mutate_mesh(text, rng):
    kind = rng.randrange(4)
    if kind == 0:
        return text[: rng.randrange(len(text))]
    lines = text.split("\n")
    i = rng.randrange(len(lines))
    if kind == 1:
        del lines[i]
    elif kind == 2:
        fields = lines[i].split(" ")
        j = rng.randrange(len(fields))
        fields[j] = rng.choice(["nan", "inf", "1e300", "-7", "0", "999999", "x"])
        lines[i] = " ".join(fields)
    else:
        lines.insert(i, lines[rng.randrange(len(lines))])
    return "\n".join(lines)


def bad_numbers(path):
    """Names of the non-finite numbers found in a CSV or JSON result file."""
    found = []
    if path.endswith(".json"):
        def flag(token):
            found.append(token)
            return 0.0
        with open(path) as f:
            json.load(f, parse_constant=flag)
    elif path.endswith(".csv"):
        with open(path) as f:
            for line in f:
                for cell in line.strip().split(","):
                    try:
                        v = float(cell)
                    except ValueError:
                        continue
                    if not math.isfinite(v):
                        found.append(cell)
    return found


# A mutation that deletes [structure] type = "lumped" leaves the default FE sector: these
# keep it small (the lumped base sets none of them, so no mutation is masked).
BOUNDED = ["--set", "geometry.mesh_size=0.03", "--set", "geometry.element_order=1", "--set", "modal.modes=4"]


def check_run(exe, workdir, case, label, command):
    out = os.path.join(workdir, "out")
    shutil.rmtree(out, ignore_errors=True)
    try:
        p = subprocess.run([exe, command, case, "--out", out, "--quiet", "--threads", "1"] + BOUNDED, cwd=workdir,
                           capture_output=True, text=True, timeout=TIMEOUT, errors="replace")
    except subprocess.TimeoutExpired:
        for n in os.listdir(workdir):  # the killed run's staging folder
            if ".staging-" in n:
                shutil.rmtree(os.path.join(workdir, n), ignore_errors=True)
        return f"{label}: no exit within {TIMEOUT} s"
    rc = p.returncode
    if rc not in (0, 2, 3):
        return f"{label}: exit {rc}: {p.stderr.strip()[-300:]}"
    if any(".staging-" in n for n in os.listdir(workdir)):
        return f"{label}: a staging folder survived the run"
    if rc == 2:
        if os.path.exists(out):
            return f"{label}: exit 2 left a results folder"
        if "error" not in p.stderr:
            return f"{label}: exit 2 without a message"
        return None
    run_json = os.path.join(out, "run.json")
    if not os.path.exists(run_json):
        return f"{label}: exit {rc} without run.json"
    with open(run_json) as f:
        status = json.load(f).get("status")
    if status != ("ok" if rc == 0 else "numerics_failed"):
        return f"{label}: exit {rc} with run.json status {status}"
    for root, _, files in os.walk(out):
        for n in files:
            bad = bad_numbers(os.path.join(root, n))
            if bad:
                return f"{label}: {n} holds {bad[:3]}"
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("exe")
    ap.add_argument("--cases", type=int, default=240)
    ap.add_argument("--meshes", type=int, default=60)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--keep")
    a = ap.parse_args()
    exe = os.path.abspath(a.exe)
    work = tempfile.mkdtemp(prefix="shroudsim_fuzz_")
    failures, counts = [], {}
    try:
        # The base cases must run clean: the mutations are measured against them.
        with open(os.path.join(work, "base.toml"), "w") as f:
            f.write(LUMPED)
        err = check_run(exe, work, "base.toml", "base lumped case", "frf")
        if err:
            raise SystemExit("base case fails: " + err)
        gen = os.path.join(work, "gen.toml")
        with open(gen, "w") as f:
            f.write('name = "gen"\n[geometry]\nelement_order = 1\nmesh_size = 0.03\n')
        subprocess.run([exe, "mesh", gen, "--out", os.path.join(work, "genout"), "--quiet"], cwd=work, check=True)
        with open(os.path.join(work, "meshes", "gen.msh")) as f:
            mesh_text = f.read()

        def run_mutated(kind, i, case, command, mutated, kept_name):
            """Runs one mutated input; a failure is recorded and, with --keep, the input kept."""
            err = check_run(exe, work, case, f"{kind} {i}", command)
            counts[kind] = counts.get(kind, 0) + 1
            if err:
                failures.append(err)
                if a.keep:
                    os.makedirs(a.keep, exist_ok=True)
                    shutil.copy(mutated, os.path.join(a.keep, kept_name))

        for i in range(a.cases):
            rng = random.Random(f"{a.seed}:case:{i}")
            text = LUMPED
            for _ in range(rng.randrange(1, 4)):
                text = mutate_text(text, rng)
            path = os.path.join(work, "c.toml")
            with open(path, "w", errors="replace") as f:
                f.write(text)
            run_mutated("case", i, "c.toml", "frf", path, f"case_{i}.toml")
        with open(os.path.join(work, "s.toml"), "w") as f:
            f.write(SECTOR)
        for i in range(a.meshes):
            rng = random.Random(f"{a.seed}:mesh:{i}")
            path = os.path.join(work, "m.msh")
            with open(path, "w") as f:
                f.write(mutate_mesh(mesh_text, rng))
            run_mutated("mesh", i, "s.toml", "mesh", path, f"mesh_{i}.msh")
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print(f"fuzz: {counts.get('case', 0)} mutated cases, {counts.get('mesh', 0)} mutated meshes, "
          f"{len(failures)} failures (seed {a.seed})")
    for f in failures:
        print("  " + f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
