#!/usr/bin/python3
"""Modal pipeline against CalculiX, side by side on the generator's meshes.

usage: tools/bench_modal_ccx.py [--case CASE] [--sizes S ...] [--modes M] [--threads T ...]
                                [--binary shroudsim] [--ccx ccx] [--work DIR]

For each mesh size: the sector is meshed once by `shroudsim mesh` (gmsh, 10-node tets), then
timed with each thread count T (default 1 and 2; T threads in every layer: shroudsim's
workers, OpenBLAS, CalculiX's solver):
  - `shroudsim modes CASE --threads T` (assembly, cyclic reduction, M modes of every harmonic
    index, modes.csv, modes.vtu, the plot), from the mesh just made, with an empty modal cache
    (and again with --no-plots: the result files only, as CalculiX writes them)
    (the case is copied into the work folder, whose modal cache entries are removed before
    each run; the mesh as read, cached by `shroudsim mesh`, is read back without gmsh);
  - `ccx` (CalculiX) on the same mesh: C3D10 elements, the hub clamped, the cyclic faces tied
    by *TIE, CYCLIC SYMMETRY and *CYCLIC SYMMETRY MODEL (N = Nb, axis z), *FREQUENCY 2 M (CalculiX
    counts each cyclic mode twice, as its two real forms),
    *SELECT CYCLIC SYMMETRY MODES NMIN = 0, NMAX = Nb / 2.
Prints a table: DOFs, the wall times, the ratio at each thread count and of the best times,
and the largest relative difference of the frequencies per nodal diameter (an independent check of the cyclic modal model: CalculiX
has its own element and its own cyclic constraint). Needs /usr/bin/python3 with meshio and
`ccx` (Debian package calculix-ccx); one run each: quote ratios from one run.
"""
import argparse
import glob
import json
import math
import os
import re
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

# meshio holds a 10-node tetrahedron in VTK order (it converts gmsh's on reading): vertices,
# then edges 01 12 20 03 13 23, which is CalculiX's C3D10 order (edges 12 23 31 14 24 34,
# 1-based).
MESHIO_TO_CCX_TET10 = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9]


def read_case_value(case, section, key):
    """A scalar from a case file (tomllib: Python >= 3.11)."""
    import tomllib
    with open(case, "rb") as f:
        return tomllib.load(f)[section][key]


def write_ccx_input(msh, inp, sectors, modes, material):
    import meshio
    m = meshio.read(msh)
    tets = [b.data for b in m.cells if b.type == "tetra10"]
    if not tets:
        raise SystemExit(f"{msh}: no tetra10 cells")
    node_sets = {}
    for name in ("hub", "cyclic_low", "cyclic_high"):
        if name not in m.cell_sets:
            raise SystemExit(f"{msh}: no physical group {name}")
        nodes = set()
        for block, idx in zip(m.cells, m.cell_sets[name]):
            if idx is not None and len(idx):
                nodes.update(int(v) for v in block.data[idx].ravel())
        node_sets[name] = sorted(nodes)
    # A clamped node cannot also be a dependent node of the cyclic tie (CalculiX refuses an
    # SPC on an MPC's dependent DOF); both sides are zero there anyway.
    hub = set(node_sets["hub"])
    node_sets["cyclic_low"] = [v for v in node_sets["cyclic_low"] if v not in hub]
    with open(inp, "w") as f:
        f.write("*HEADING\nshroudsim sector, cyclic symmetry modes\n*NODE, NSET=NALL\n")
        for i, p in enumerate(m.points):
            f.write(f"{i + 1},{p[0]:.12e},{p[1]:.12e},{p[2]:.12e}\n")
        f.write("*ELEMENT, TYPE=C3D10, ELSET=EALL\n")
        e = 0
        for block in tets:
            for c in block:
                e += 1
                ids = [int(c[k]) + 1 for k in MESHIO_TO_CCX_TET10]
                f.write(f"{e}," + ",".join(map(str, ids[:9])) + ",\n" + f"{ids[9]}\n")
        for name, nodes in node_sets.items():
            f.write(f"*NSET, NSET={name.upper()}\n")
            for k in range(0, len(nodes), 12):
                f.write(",".join(str(v + 1) for v in nodes[k:k + 12]) + "\n")
        f.write("*BOUNDARY\nHUB,1,3\n")
        f.write(f"*MATERIAL, NAME=STEEL\n*ELASTIC\n{material['E']},{material['nu']}\n"
                f"*DENSITY\n{material['rho']}\n*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL\n")
        f.write("*SURFACE, NAME=SLOW, TYPE=NODE\nCYCLIC_LOW\n*SURFACE, NAME=SHIGH, TYPE=NODE\nCYCLIC_HIGH\n")
        # Dependent (low) to independent (high): the rotation from the low face to the high face.
        f.write("*TIE, NAME=CYC, CYCLIC SYMMETRY, POSITION TOLERANCE=1e-6\nSLOW,SHIGH\n")
        f.write(f"*CYCLIC SYMMETRY MODEL, N={sectors}, NGRAPH=1, TIE=CYC\n0.,0.,0.,0.,0.,1.\n")
        f.write(f"*STEP\n*FREQUENCY\n{2 * modes}\n*SELECT CYCLIC SYMMETRY MODES, NMIN=0, NMAX={sectors // 2}\n*END STEP\n")
    return 3 * len(m.points)


def ccx_frequencies(dat):
    """{nodal diameter: [Hz, ...]} from a CalculiX .dat file of a cyclic frequency step: the
    rows "ND, MODE NO, EIGENVALUE, RAD/TIME, CYCLES/TIME, IMAGINARY" of the eigenvalue output
    blocks. CalculiX lists each cyclic mode twice (its two real forms): consecutive equal
    frequencies count once."""
    out = {}
    in_block = False
    with open(dat) as f:
        for line in f:
            if "E I G E N V A L U E" in line:
                in_block = True
                continue
            if "P A R T I C I P A T I O N" in line or "E F F E C T I V E" in line:
                in_block = False
                continue
            parts = line.split()
            if not in_block or len(parts) != 6 or not (parts[0].isdigit() and parts[1].isdigit()):
                continue
            hz = float(parts[4])
            fs = out.setdefault(int(parts[0]), [])
            if fs and abs(fs[-1] - hz) <= 1e-9 * hz:
                continue
            fs.append(hz)
    return out


def shroudsim_frequencies(csv_path):
    import csv
    out = {}
    with open(csv_path, newline="") as f:
        for r in csv.DictReader(f):
            if r["harmonic_index"] != r["nodal_diameter"]:
                continue  # h and Nb - h are the same nodal diameter
            out.setdefault(int(r["nodal_diameter"]), []).append(float(r["frequency_hz"]))
    return out


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--case", default=os.path.join(ROOT, "cases", "shrouded_blade.toml"))
    ap.add_argument("--sizes", type=float, nargs="+", default=[0.018, 0.0117, 0.0075])
    ap.add_argument("--modes", type=int, default=10)
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--binary", default=os.path.join(ROOT, "build", "src", "app", "shroudsim"))
    ap.add_argument("--ccx", default="ccx")
    ap.add_argument("--work", default="/tmp/bench_modal_ccx")
    a = ap.parse_args(argv[1:])
    if shutil.which(a.ccx) is None:
        print(f"bench_modal_ccx: {a.ccx} not found (apt-get install calculix-ccx)", file=sys.stderr)
        return 2
    binary = os.path.abspath(a.binary)
    case = os.path.abspath(a.case)
    sectors = int(read_case_value(case, "structure", "sectors"))
    material = {"E": read_case_value(case, "material", "youngs_modulus"),
                "nu": read_case_value(case, "material", "poisson_ratio"),
                "rho": read_case_value(case, "material", "density")}
    name = os.path.splitext(os.path.basename(case))[0]
    rows = []
    for size in a.sizes:
        work = os.path.join(a.work, f"h{size:g}")
        shutil.rmtree(work, ignore_errors=True)
        os.makedirs(work)
        # The case is copied into the work folder: the modal cache lives beside the case file
        # (`.cache`, emptied before each timed run), and a cached stage would time a lookup
        # instead of the modal solve.
        local_case = os.path.join(work, os.path.basename(case))
        shutil.copy(case, local_case)
        sets = ["--set", f"geometry.mesh_size={size}", "--set", f"modal.modes={a.modes}",
                "--set", 'modal.harmonic_indices="all"']
        subprocess.run([binary, "mesh", local_case, "--out", os.path.join(work, "mesh"), "--quiet"] + sets, cwd=work,
                       check=True)
        msh = os.path.join(work, "meshes", f"{name}.msh")
        if not os.path.exists(msh):
            found = [f for f in os.listdir(os.path.join(work, "meshes")) if f.endswith(".msh")]
            msh = os.path.join(work, "meshes", found[0])
        dofs = write_ccx_input(msh, os.path.join(work, "sector.inp"), sectors, a.modes, material)
        ours, bare, theirs, stages = {}, {}, {}, {}
        for t in a.threads:
            # T threads in every layer: shroudsim's workers and the BLAS (OpenBLAS otherwise
            # starts one thread per core whatever --threads says), CalculiX's solver threads.
            env = dict(os.environ, OMP_NUM_THREADS=str(t), OPENBLAS_NUM_THREADS=str(t),
                       CCX_NPROC_EQUATION_SOLVER=str(t), CCX_NPROC_STIFFNESS=str(t))
            def timed_modes(out, extra):
                """`shroudsim modes` from an empty modal cache: (wall seconds, run.json stage times), or
                None when the modal stage was reused all the same. The modal entries only are removed:
                the mesh entry the `mesh` command left (the mesh as read and checked,
                .cache/mesh-*.bin) stays, as in a user's second command on a mesh."""
                for entry in glob.glob(os.path.join(work, ".cache", "modes-*")):
                    os.remove(entry)
                t0 = time.perf_counter()
                subprocess.run([binary, "modes", local_case, "--out", out, "--quiet", "--threads", str(t)] + extra +
                               sets, cwd=work, env=env, check=True)
                seconds = time.perf_counter() - t0
                with open(os.path.join(out, "run.json")) as f:
                    run = json.load(f)
                if any(st["name"] == "modes" and st["reused"] for st in run["stages"]):
                    return None
                return seconds, {st["name"]: st["seconds"] for st in run["stages"]}

            with_plot = timed_modes(os.path.join(work, f"modes{t}"), [])
            without = timed_modes(os.path.join(work, f"modes{t}-bare"), ["--no-plots"])
            if with_plot is None or without is None:
                print(f"bench_modal_ccx: the modal stage was reused from a cache at {size}", file=sys.stderr)
                return 1
            ours[t], stages[t] = with_plot
            bare[t] = without[0]
            t0 = time.perf_counter()
            r = subprocess.run([a.ccx, "-i", "sector"], cwd=work, env=env, stdout=subprocess.DEVNULL,
                               stderr=subprocess.PIPE, text=True)
            theirs[t] = time.perf_counter() - t0
            if r.returncode != 0:
                print(f"bench_modal_ccx: ccx failed at mesh size {size}: {r.stderr[-500:]}", file=sys.stderr)
                return 1
        f_ours = shroudsim_frequencies(os.path.join(work, f"modes{a.threads[0]}", "modes.csv"))
        f_theirs = ccx_frequencies(os.path.join(work, "sector.dat"))
        worst = 0.0
        for nd, fs in f_ours.items():
            other = sorted(f_theirs.get(nd, []))[:len(fs)]
            for f1, f2 in zip(sorted(fs), other):
                worst = max(worst, abs(f1 - f2) / f2)
        compared = sum(min(len(fs), len(f_theirs.get(nd, []))) for nd, fs in f_ours.items())
        rows.append((size, dofs, ours, bare, theirs, stages, worst, compared))
        print(f"mesh_size {size:g}: {dofs} DOFs, shroudsim " +
              ", ".join(f"{ours[t]:.1f} s ({t} thr.)" for t in a.threads) + " (--no-plots " +
              ", ".join(f"{bare[t]:.1f} s" for t in a.threads) + "); ccx " +
              ", ".join(f"{theirs[t]:.1f} s ({t} thr.)" for t in a.threads) +
              f"; max rel. freq. diff. {worst:.2e} over {compared} modes", file=sys.stderr, flush=True)
    print(f"modes per nodal diameter: {a.modes}, Nb = {sectors}, case {os.path.basename(case)}")
    head = "| mesh_size | DOFs | " + " | ".join(f"shroudsim {t} thr. (s)" for t in a.threads) + " | " + \
        " | ".join(f"--no-plots {t} thr. (s)" for t in a.threads) + " | " + \
        " | ".join(f"ccx {t} thr. (s)" for t in a.threads) + " | " + \
        " | ".join(f"ratio at {t} thr." for t in a.threads) + \
        " | best / best | best / best, --no-plots | max rel. freq. diff. (modes) |"
    print(head)
    print("|" + " --- |" * (head.count("|") - 1))
    for size, dofs, ours, bare, theirs, stages, worst, n in rows:
        best = min(theirs.values()) / min(ours.values())
        best_bare = min(theirs.values()) / min(bare.values())
        print(f"| {size:g} | {dofs:,} | " + " | ".join(f"{ours[t]:.1f}" for t in a.threads) + " | " +
              " | ".join(f"{bare[t]:.1f}" for t in a.threads) + " | " +
              " | ".join(f"{theirs[t]:.1f}" for t in a.threads) + " | " +
              " | ".join(f"{theirs[t] / ours[t]:.1f}x" for t in a.threads) +
              f" | {best:.1f}x | {best_bare:.1f}x | {worst:.2e} ({n}) |")
    print()
    print("Where shroudsim's time goes (run.json stages, s; the rest: start-up, output files, the plot):")
    print("| mesh_size | threads | mesh (read) | assembly | modes | rest |")
    print("| --- | --- | --- | --- | --- | --- |")
    for size, dofs, ours, bare, theirs, stages, worst, n in rows:
        for t in a.threads:
            st = stages[t]
            known = sum(st.get(k, 0.0) for k in ("mesh", "assembly", "modes"))
            print(f"| {size:g} | {t} | {st.get('mesh', 0.0):.2f} | {st.get('assembly', 0.0):.2f} | "
                  f"{st.get('modes', 0.0):.2f} | {ours[t] - known:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
