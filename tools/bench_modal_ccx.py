#!/usr/bin/python3
"""Modal pipeline against CalculiX, side by side on the generator's meshes.

usage: tools/bench_modal_ccx.py [--case CASE] [--sizes S ...] [--modes M] [--threads T]
                                [--binary shroudsim] [--ccx ccx] [--work DIR]

For each mesh size: the sector is meshed once by `shroudsim mesh` (gmsh, 10-node tets), then
timed, each with T solver threads:
  - `shroudsim modes CASE` (assembly, cyclic reduction, M modes of every harmonic index,
    modes.csv, modes.vtu, the plot), from the mesh just made, with an empty modal cache (the
    case is copied into the work folder, whose `.cache` starts empty);
  - `ccx` (CalculiX) on the same mesh: C3D10 elements, the hub clamped, the cyclic faces tied
    by *TIE, CYCLIC SYMMETRY and *CYCLIC SYMMETRY MODEL (N = Nb, axis z), *FREQUENCY 2 M (CalculiX
    counts each cyclic mode twice, as its two real forms),
    *SELECT CYCLIC SYMMETRY MODES NMIN = 0, NMAX = Nb / 2.
Prints a table: DOFs, the two wall times, their ratio, and the largest relative difference of
the frequencies per nodal diameter (an independent check of the cyclic modal model: CalculiX
has its own element and its own cyclic constraint). Needs /usr/bin/python3 with meshio and
`ccx` (Debian package calculix-ccx); one run each: quote ratios from one run.
"""
import argparse
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
    ap.add_argument("--threads", type=int, default=1)
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
    env = dict(os.environ, OMP_NUM_THREADS=str(a.threads), CCX_NPROC_EQUATION_SOLVER=str(a.threads),
               CCX_NPROC_STIFFNESS=str(a.threads))
    rows = []
    for size in a.sizes:
        work = os.path.join(a.work, f"h{size:g}")
        shutil.rmtree(work, ignore_errors=True)
        os.makedirs(work)
        # The case is copied into the work folder: the modal cache lives beside the case file
        # (`.cache`), and a cached stage would time a lookup instead of the modal solve.
        local_case = os.path.join(work, os.path.basename(case))
        shutil.copy(case, local_case)
        sets = ["--set", f"geometry.mesh_size={size}", "--set", f"modal.modes={a.modes}",
                "--set", 'modal.harmonic_indices="all"']
        common = ["--quiet", "--threads", str(a.threads)]
        subprocess.run([binary, "mesh", local_case, "--out", os.path.join(work, "mesh")] + sets + common, cwd=work,
                       check=True)
        t0 = time.perf_counter()
        subprocess.run([binary, "modes", local_case, "--out", os.path.join(work, "modes")] + sets + common, cwd=work,
                       check=True)
        t_ours = time.perf_counter() - t0
        with open(os.path.join(work, "modes", "run.json")) as f:
            import json
            if any(st["name"] == "modes" and st["reused"] for st in json.load(f)["stages"]):
                print(f"bench_modal_ccx: the modal stage was reused from a cache at {size}", file=sys.stderr)
                return 1
        msh = os.path.join(work, "meshes", f"{name}.msh")
        if not os.path.exists(msh):
            found = [f for f in os.listdir(os.path.join(work, "meshes")) if f.endswith(".msh")]
            msh = os.path.join(work, "meshes", found[0])
        dofs = write_ccx_input(msh, os.path.join(work, "sector.inp"), sectors, a.modes, material)
        t0 = time.perf_counter()
        r = subprocess.run([a.ccx, "-i", "sector"], cwd=work, env=env, stdout=subprocess.DEVNULL,
                           stderr=subprocess.PIPE, text=True)
        t_ccx = time.perf_counter() - t0
        if r.returncode != 0:
            print(f"bench_modal_ccx: ccx failed at mesh size {size}: {r.stderr[-500:]}", file=sys.stderr)
            return 1
        ours = shroudsim_frequencies(os.path.join(work, "modes", "modes.csv"))
        theirs = ccx_frequencies(os.path.join(work, "sector.dat"))
        worst = 0.0
        for nd, fs in ours.items():
            other = sorted(theirs.get(nd, []))[:len(fs)]
            for f1, f2 in zip(sorted(fs), other):
                worst = max(worst, abs(f1 - f2) / f2)
        compared = sum(min(len(fs), len(theirs.get(nd, []))) for nd, fs in ours.items())
        rows.append((size, dofs, t_ours, t_ccx, worst, compared))
        print(f"mesh_size {size:g}: {dofs} DOFs, shroudsim {t_ours:.1f} s, ccx {t_ccx:.1f} s, "
              f"max rel. freq. diff. {worst:.2e} over {compared} modes", file=sys.stderr, flush=True)
    print(f"modes per nodal diameter: {a.modes}, Nb = {sectors}, threads: {a.threads}, case {os.path.basename(case)}")
    print("| mesh_size | DOFs | shroudsim `modes` (s) | ccx (s) | ccx / shroudsim | max rel. freq. diff. (modes compared) |")
    print("| --- | --- | --- | --- | --- | --- |")
    for size, dofs, t1, t2, worst, n in rows:
        print(f"| {size:g} | {dofs:,} | {t1:.1f} | {t2:.1f} | {t2 / t1:.1f}x | {worst:.2e} ({n}) |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
