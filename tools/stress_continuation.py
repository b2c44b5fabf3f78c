#!/usr/bin/env python3
"""Stress benchmark of the forced-response continuation on random lumped friction models.

Draws a seeded corpus of random lumped models (1 to 6 DOFs, one contact element, contact
model 1d / quasi3d / full3d, preloads from a gap through zero to heavy, contact stiffness
over four to six decades, light to heavy damping, H = 1..15), writes one case file each,
runs `shroudsim frf CASE --quiet --out DIR --threads 1` on every one with the DEFAULT
continuation settings (continuation.initial_step and max_points are never set), and prints a
table, one line per failure and a summary.

  python3 tools/stress_continuation.py                       # 200 models, seed 1, 2 jobs
  python3 tools/stress_continuation.py --count 50 --seed 7 --csv /tmp/stress.csv
  python3 tools/stress_continuation.py --set response.stability=false   # the continuation alone

The stress models the tests and docs/ name by number ("stress corpus model 8") are of seed 1
drawn with --raw-preload (the corpus before 2026-12-05; their case files are in the tests).

The corpus depends only on --seed (model i is drawn from its own generator seeded with
"seed:i", so the first k models are the same whatever --count is). Pure Python (no numpy):
the models are at most 6 x 6, and the script runs under any python3.

How a model is drawn (every parameter is recorded in the CSV and the failure lines):
- contact model uniform over 1d, quasi3d, full3d; DOFs n uniform in 1..6 (1d) or 3..6
  (quasi3d and full3d need three DOFs for the x, y, z directions of the contact node);
- structure: a spring chain (springs and masses within a factor 3 of each other, the first
  DOF to ground, the last one to ground or free) or a random SPD stiffness Q diag(l) Q^T
  with l in 1..30 (well conditioned); masses diagonal, positive, 1e-2..1e2 kg scale;
  K is scaled so that the first natural frequency f1 is log-uniform in 1e-2..1e4 Hz;
- damping: stiffness-proportional C = (2 zeta / w1) K, or Rayleigh C = a M + b K with the
  ratio zeta at the first and the last mode; zeta log-uniform in 1e-4..1e-1 (symmetric PSD);
- contact: kt / k and kn / k log-uniform in 1e-2..1e4, with k the mean of diag(K);
  mu uniform in 0.05..1; the element acts to ground, or (30 %) against other DOFs;
  quasi3d/full3d: the contact node's x, y, z are three distinct DOFs, z is the normal
  (z > 0 presses), frame angle 0 or uniform in 0..90 degrees;
- preload regime: "pressed" (N0 > 0), "zero" (N0 = 0) or, for quasi3d/full3d only, "gap"
  (N0 < 0: an initial gap g = -N0/kn; the 1d law has a constant normal load and refuses a
  negative preload). Pressed: the load the contact carries at rest, N_s, is drawn log-uniform
  in 1e-3..1e3; the case's normal_preload N0 acts at zero relative displacement and the
  structure gives way under it, so N0 = N_s / (N_s / N0 of the stuck structure at rest)
  (--raw-preload: N0 = the drawn load, the corpus before 2026-12-05, whose contacts carried
  1e-4..1 of it at rest); the static tangential load at rest against mu N_s is recorded
  (static_tangential: above 1 the contact slips at rest already);
- excitation force: sized so that the linear response is r times the reference length,
  r log-uniform in 0.3..30: pressed: the peak tangential contact motion of the STUCK
  linear system (contact springs kt, and kn in the normal) over the range against the slip
  displacement mu N_s / kt (r < 1: stays stuck; r > 1: slips); gap: the peak normal contact
  motion of the FREE system against the gap (r > 1: the contact closes); zero: the problem
  is homogeneous in the force, which is sized for a free contact motion of 1e-6..1e-2 m.
  For pressed contacts the separation ratio s = kn max|w_z| / N_s of the stuck system is
  recorded too (s > 1: the contact opens over part of the period);
- frequency range around a resonance: centre = the free first mode (55 %), a random free
  mode (20 %) or the first mode of the stuck system (25 %, pressed contacts only; else a
  random free mode), from 0.5..0.8 to 1.25..1.8 times the centre, swept downward in 10 %;
- hbm.harmonics H uniform in 1..15, hbm.time_samples N = the smallest power of two
  >= max(64, 4 (2H + 1)) (hbm.raise_time_samples stays at its default, on: a curve that
  stops at the sampled law's corners is traced again with 4 N, 16 N; the summary counts
  those, the CSV has the N of each result and raised_from).

Exit classes: ok (0), bad_input (2: a generator bug), numerics (3), timeout, other (any
other status or a signal). Case files stay in OUT/cases/, results of failing runs in
OUT/runs/<name>/ (those of runs that exit 0 are removed unless --keep-results);
OUT/failures.txt lists the failing cases.
"""
import argparse
import cmath
import concurrent.futures
import csv
import hashlib
import json
import math
import os
import random
import shutil
import statistics
import subprocess
import sys
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TWO_PI = 2.0 * math.pi


# ---------------------------------------------------------------------------------------
# Small dense linear algebra (n <= 6), pure Python.

def zeros(n, m=None):
    return [[0.0] * (n if m is None else m) for _ in range(n)]


def jacobi_eigh(a):
    """Eigenvalues and eigenvectors (columns) of the symmetric matrix a (cyclic Jacobi)."""
    n = len(a)
    a = [row[:] for row in a]
    v = [[1.0 if i == j else 0.0 for j in range(n)] for i in range(n)]
    for _ in range(100):
        off = sum(a[i][j] ** 2 for i in range(n) for j in range(n) if i != j)
        scale = sum(a[i][i] ** 2 for i in range(n))
        if off <= 1e-30 * scale or off == 0.0:
            break
        for p in range(n - 1):
            for q in range(p + 1, n):
                if a[p][q] == 0.0:
                    continue
                theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q])
                t = math.copysign(1.0, theta) / (abs(theta) + math.sqrt(theta * theta + 1.0))
                c = 1.0 / math.sqrt(t * t + 1.0)
                s = t * c
                for k in range(n):
                    akp, akq = a[k][p], a[k][q]
                    a[k][p] = c * akp - s * akq
                    a[k][q] = s * akp + c * akq
                for k in range(n):
                    apk, aqk = a[p][k], a[q][k]
                    a[p][k] = c * apk - s * aqk
                    a[q][k] = s * apk + c * aqk
                for k in range(n):
                    vkp, vkq = v[k][p], v[k][q]
                    v[k][p] = c * vkp - s * vkq
                    v[k][q] = s * vkp + c * vkq
    vals = [a[i][i] for i in range(n)]
    order = sorted(range(n), key=lambda i: vals[i])
    return [vals[i] for i in order], [[v[k][i] for i in order] for k in range(n)]


def natural_frequencies_hz(k, mdiag):
    """sqrt(eig(K, M)) / 2 pi for a diagonal M (ascending)."""
    n = len(k)
    a = [[k[i][j] / math.sqrt(mdiag[i] * mdiag[j]) for j in range(n)] for i in range(n)]
    vals, _ = jacobi_eigh(a)
    return [math.sqrt(max(l, 0.0)) / TWO_PI for l in vals]


def solve_complex(a, b):
    """Solves a x = b (complex, Gaussian elimination with partial pivoting)."""
    n = len(a)
    m = [list(a[i]) + [b[i]] for i in range(n)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(m[r][c]))
        m[c], m[p] = m[p], m[c]
        piv = m[c][c]
        if piv == 0:
            raise ZeroDivisionError("singular dynamic stiffness")
        for r in range(c + 1, n):
            f = m[r][c] / piv
            if f != 0:
                for j in range(c, n + 1):
                    m[r][j] -= f * m[c][j]
    x = [0j] * n
    for i in range(n - 1, -1, -1):
        s = m[i][n] - sum(m[i][j] * x[j] for j in range(i + 1, n))
        x[i] = s / m[i][i]
    return x


def random_orthogonal(rng, n):
    """Gram-Schmidt on a Gaussian matrix (columns)."""
    cols = []
    while len(cols) < n:
        v = [rng.gauss(0.0, 1.0) for _ in range(n)]
        for _ in range(2):
            for c in cols:
                d = sum(x * y for x, y in zip(v, c))
                v = [x - d * y for x, y in zip(v, c)]
        norm = math.sqrt(sum(x * x for x in v))
        if norm > 1e-3:
            cols.append([x / norm for x in v])
    return [[cols[j][i] for j in range(n)] for i in range(n)]


def symmetrize(a):
    n = len(a)
    for i in range(n):
        for j in range(i + 1, n):
            a[j][i] = a[i][j]
    return a


def log_uniform(rng, lo, hi):
    return 10.0 ** rng.uniform(math.log10(lo), math.log10(hi))


def pow2_at_least(v):
    p = 1
    while p < v:
        p *= 2
    return p


# ---------------------------------------------------------------------------------------
# The corpus.

def contact_motion_peak(k, mdiag, c, dirs, exc, freqs):
    """Largest over freqs of the contact relative motion per unit force at DOF exc:
    returns (tangential peak sqrt(|wx|^2 + |wy|^2), normal peak |wz|) of the system
    (k, M, c); dirs = [(dof, other), ...] for x, y, z (dof -1: absent)."""
    n = len(k)
    tmax = zmax = 0.0
    for f in freqs:
        w = TWO_PI * f
        dyn = [[complex(k[i][j] - (w * w * mdiag[i] if i == j else 0.0), w * c[i][j]) for j in range(n)]
               for i in range(n)]
        rhs = [0j] * n
        rhs[exc] = 1.0
        try:
            u = solve_complex(dyn, rhs)
        except ZeroDivisionError:
            continue
        rel = []
        for d, o in dirs:
            rel.append(0j if d < 0 else u[d] - (u[o] if o >= 0 else 0.0))
        while len(rel) < 3:
            rel.append(0j)
        tmax = max(tmax, math.sqrt(abs(rel[0]) ** 2 + abs(rel[1]) ** 2))
        zmax = max(zmax, abs(rel[2]))
    return tmax, zmax


def stuck_static_state(ks, dirs, kn, kt, mu):
    """The stuck contact at rest under a unit preload (quasi3d, full3d): the structure with the
    contact springs, ks u = -b_z (the preload pushes the contact's normal DOF back, b_z its
    relative normal motion's row), gives the load the contact carries, N_s = 1 + kn w_z, and
    its tangential load kt |(w_x, w_y)| with the sliders at rest. Returns (N_s, tangential
    load / (mu N_s)): above 1 the contact already slips at rest."""
    n = len(ks)
    b = [[0.0] * n for _ in range(3)]
    for d, (dof, oth) in enumerate(dirs):
        if dof >= 0:
            b[d][dof] += 1.0
            if oth >= 0:
                b[d][oth] -= 1.0
    u = [x.real for x in solve_complex([[complex(v) for v in row] for row in ks], [complex(-v) for v in b[2]])]
    w = [sum(b[d][i] * u[i] for i in range(n)) for d in range(3)]
    load = 1.0 + kn * w[2]
    return load, kt * math.hypot(w[0], w[1]) / (mu * load)


def add_spring(k, kval, d, o):
    """Adds a spring of stiffness kval between DOF d and DOF o (-1: ground)."""
    k[d][d] += kval
    if o >= 0:
        k[o][o] += kval
        k[d][o] -= kval
        k[o][d] -= kval


def sample_freqs(lo, hi, extra):
    fs = [lo + (hi - lo) * i / 399.0 for i in range(400)]
    fs += [f for f in extra if lo <= f <= hi]
    return fs


def draw_model(seed, index, raw_preload=False):
    rng = random.Random("shroudsim-stress:%d:%d" % (seed, index))
    p = {"name": "stress_%04d" % index, "index": index}
    model = rng.choice(["1d", "quasi3d", "full3d"])
    three_d = model != "1d"
    n = rng.randint(3, 6) if three_d else rng.randint(1, 6)
    p["model"], p["n"] = model, n

    # Structure: masses, stiffness shape, then scaled to the first natural frequency.
    m0 = log_uniform(rng, 1e-2, 1e2)
    mdiag = [m0 * log_uniform(rng, 1.0 / 3.0, 3.0) for _ in range(n)]
    structure = rng.choice(["chain", "spd"])
    k = zeros(n)
    if structure == "chain":
        for i in range(n):
            add_spring(k, log_uniform(rng, 1.0 / 3.0, 3.0), i, i - 1)
        if n > 1 and rng.random() < 0.5:
            add_spring(k, log_uniform(rng, 1.0 / 3.0, 3.0), n - 1, -1)
            structure = "chain_fixed_fixed"
    else:
        q = random_orthogonal(rng, n)
        lam = [log_uniform(rng, 1.0, 30.0) for _ in range(n)]
        for i in range(n):
            for j in range(i, n):
                k[i][j] = sum(q[i][r] * lam[r] * q[j][r] for r in range(n))
        symmetrize(k)
    f1 = log_uniform(rng, 1e-2, 1e4)
    scale = (f1 / natural_frequencies_hz(k, mdiag)[0]) ** 2
    k = symmetrize([[k[i][j] * scale for j in range(n)] for i in range(n)])
    free_modes = natural_frequencies_hz(k, mdiag)
    w1, wn = TWO_PI * free_modes[0], TWO_PI * free_modes[-1]
    p["structure"], p["m0"], p["f1_hz"] = structure, m0, free_modes[0]

    zeta = log_uniform(rng, 1e-4, 1e-1)
    if rng.random() < 0.5:
        damping, a, b = "stiffness", 0.0, 2.0 * zeta / w1
    else:
        damping, a, b = "rayleigh", 2.0 * zeta * w1 * wn / (w1 + wn), 2.0 * zeta / (w1 + wn)
    c = symmetrize([[b * k[i][j] + (a * mdiag[i] if i == j else 0.0) for j in range(n)] for i in range(n)])
    p["damping"], p["zeta"] = damping, zeta

    # Contact element.
    k_typ = sum(k[i][i] for i in range(n)) / n
    kt_ratio, kn_ratio = log_uniform(rng, 1e-2, 1e4), log_uniform(rng, 1e-2, 1e4)
    kt, kn = kt_ratio * k_typ, kn_ratio * k_typ
    mu = rng.uniform(0.05, 1.0)
    if three_d:
        perm = list(range(n))
        rng.shuffle(perm)
        node = perm[:3]
        other = perm[3:6] if (n == 6 and rng.random() < 0.3) else [-1, -1, -1]
        frame = 0.0 if rng.random() < 0.5 else rng.uniform(0.0, 90.0)
    else:
        node = [rng.randrange(n)]
        other = [-1]
        if n >= 2 and rng.random() < 0.3:
            other = [rng.choice([d for d in range(n) if d != node[0]])]
        frame = 0.0
    dirs = list(zip(node, other))
    p.update(kt_ratio=kt_ratio, kn_ratio=kn_ratio, kt=kt, kn=kn, mu=mu, frame_deg=frame,
             contact_dofs=" ".join(map(str, node)), other_dofs=" ".join(map(str, other)))

    # Stuck linear system: contact springs in every direction of the element.
    ks = [row[:] for row in k]
    for d, (dof, oth) in enumerate(dirs):
        add_spring(ks, kn if d == 2 else kt, dof, oth)
    symmetrize(ks)
    stuck_modes = natural_frequencies_hz(ks, mdiag)

    u = rng.random()
    if three_d:
        regime = "gap" if u < 0.25 else "zero" if u < 0.40 else "pressed"
    else:
        regime = "zero" if u < 0.05 else "pressed"
    p["regime"] = regime

    exc = rng.randrange(n)
    resp = node[0] if rng.random() < 0.5 else rng.randrange(n)
    p["excitation_dof"], p["response_dof"] = exc, resp

    # Frequency range around a resonance.
    v = rng.random()
    if v < 0.55:
        centre, around = free_modes[0], "free_mode_1"
    elif v < 0.75 or regime != "pressed":
        j = rng.randrange(n)
        centre, around = free_modes[j], "free_mode_%d" % (j + 1)
    else:
        centre, around = stuck_modes[0], "stuck_mode_1"
    lo, hi = centre * rng.uniform(0.5, 0.8), centre * rng.uniform(1.25, 1.8)
    down = rng.random() < 0.1
    p["around"], p["centre_hz"] = around, centre
    p["f_start_hz"], p["f_end_hz"] = (hi, lo) if down else (lo, hi)

    harmonics = rng.randint(1, 15)
    p["H"], p["N"] = harmonics, pow2_at_least(max(64, 4 * (2 * harmonics + 1)))

    # Excitation level.
    r = log_uniform(rng, 0.3, 30.0)
    freqs_stuck = sample_freqs(lo, hi, stuck_modes)
    freqs_free = sample_freqs(lo, hi, free_modes)
    separation = float("nan")
    static_load_ratio = static_tangential = float("nan")
    if regime == "pressed":
        # n_c: the normal load the contact carries at rest. The case's preload N0 acts at zero
        # relative displacement and the structure gives way under it (docs/physics.md section 3):
        # at rest the stuck contact carries N0 * static_load_ratio (quasi3d, full3d; the 1d law's
        # normal load is N0 itself), so N0 is drawn for that load, and the slip displacement and
        # the separation ratio are those of the load it carries.
        n_c = log_uniform(rng, 1e-3, 1e3)
        n0 = n_c
        if three_d:
            static_load_ratio, static_tangential = stuck_static_state(ks, dirs, kn, kt, mu)
            if not raw_preload:
                n0 = n_c / static_load_ratio
        slip = mu * n_c / kt
        tpk, zpk = contact_motion_peak(ks, mdiag, c, dirs, exc, freqs_stuck)
        force = r * slip / tpk
        if three_d:
            separation = kn * zpk * force / n_c
        reference = "slip %.3g m" % slip
    elif regime == "gap":
        gap = log_uniform(rng, 1e-6, 1e-2)
        n0 = -kn * gap
        tpk, zpk = contact_motion_peak(k, mdiag, c, dirs, exc, freqs_free)
        force = r * gap / zpk
        reference = "gap %.3g m" % gap
    else:
        n0 = 0.0
        r = float("nan")
        tpk, zpk = contact_motion_peak(k, mdiag, c, dirs, exc, freqs_free)
        amp = log_uniform(rng, 1e-6, 1e-2)
        force = amp / max(math.hypot(tpk, zpk), 1e-300)
        reference = "free motion %.3g m" % amp
    if not (math.isfinite(force) and force > 0.0):
        raise RuntimeError("%s: force %r (linear response %r, %r)" % (p["name"], force, tpk, zpk))
    p.update(N0=n0, r=r, separation=separation, force=force, reference=reference,
             static_load_ratio=static_load_ratio, static_tangential=static_tangential)
    if regime == "pressed":
        p["expect"] = ("slip" if r > 1.0 else "stick") + ("+separation" if separation > 1.0 else "")
    elif regime == "gap":
        p["expect"] = "closes" if r > 1.0 else "open"
    else:
        p["expect"] = "homogeneous" if three_d else "free (mu N0 = 0)"

    p["toml"] = case_toml(p, mdiag, k, c, node, other, frame, three_d)
    return p


def fnum(x):
    """A TOML float that round-trips."""
    x = float(x)
    if not math.isfinite(x):
        raise ValueError("non-finite number %r" % x)
    return repr(x)


def matrix_toml(a):
    return "[" + ", ".join("[" + ", ".join(fnum(x) for x in row) + "]" for row in a) + "]"


def case_toml(p, mdiag, k, c, node, other, frame, three_d):
    n = len(k)
    mass = [[mdiag[i] if i == j else 0.0 for j in range(n)] for i in range(n)]
    lines = [
        "# shroudsim stress corpus: %s (tools/stress_continuation.py)" % p["name"],
        "# %s" % describe(p),
        'name = "%s"' % p["name"],
        "",
        "[structure]",
        'type = "lumped"',
        "sectors = 1",
        "mass = " + matrix_toml(mass),
        "stiffness = " + matrix_toml(k),
        "damping = " + matrix_toml(c),
        "",
        "[excitation]",
        "force = " + fnum(p["force"]),
        "dof = %d" % p["excitation_dof"],
        "",
        "[response]",
        "dof = %d" % p["response_dof"],
        "",
        "[contact]",
        'model = "%s"' % p["model"],
        "friction_coefficient = " + fnum(p["mu"]),
        "tangential_stiffness = " + fnum(p["kt"]),
        "normal_stiffness = " + fnum(p["kn"]),
        "normal_preload = " + fnum(p["N0"]),
    ]
    if three_d:
        lines.append("frame_angle_deg = " + fnum(frame))
    lines += ["", "[[contact.elements]]"]
    for axis, d, o in zip("xyz", node, other):
        lines.append("%s_dof = %d" % (axis, d))
        if o >= 0:
            lines.append("other_%s_dof = %d" % (axis, o))
    lines += [
        "",
        "[hbm]",
        "harmonics = %d" % p["H"],
        "time_samples = %d" % p["N"],
        "",
        "[continuation]",
        "frequency_start_hz = " + fnum(p["f_start_hz"]),
        "frequency_end_hz = " + fnum(p["f_end_hz"]),
        "",
    ]
    return "\n".join(lines)


def describe(p):
    return ("%s n=%d %s f1=%.4g Hz range %.4g..%.4g Hz (%s) zeta=%.3g (%s) kt/k=%.3g kn/k=%.3g mu=%.3g "
            "N0=%.4g (%s, %s) r=%.3g sep=%.3g -> %s H=%d N=%d exc=%d resp=%d contact=[%s] other=[%s] frame=%.3g"
            "%s"
            % (p["model"], p["n"], p["structure"], p["f1_hz"], p["f_start_hz"], p["f_end_hz"], p["around"],
               p["zeta"], p["damping"], p["kt_ratio"], p["kn_ratio"], p["mu"], p["N0"], p["regime"],
               p["reference"], p["r"], p["separation"], p["expect"], p["H"], p["N"], p["excitation_dof"],
               p["response_dof"], p["contact_dofs"], p["other_dofs"], p["frame_deg"],
               "" if not math.isfinite(p["static_load_ratio"]) else
               " at rest: N = %.3g N0, tangential %.3g mu N" % (p["static_load_ratio"], p["static_tangential"])))


# ---------------------------------------------------------------------------------------
# Running.

FRF_FIELDS = ["status", "message", "points", "pieces", "turning_points", "peak_amplitude_m",
              "peak_frequency_hz", "max_energy_balance_error", "time_samples"]


def run_case(p, binary, out, timeout, sets=()):
    case = os.path.join(out, "cases", p["name"] + ".toml")
    rdir = os.path.join(out, "runs", p["name"])
    shutil.rmtree(rdir, ignore_errors=True)
    cmd = [binary, "frf", case, "--quiet", "--out", rdir, "--threads", "1"]
    for s in sets:
        cmd += ["--set", s]
    row = {"exit": None, "exit_class": None, "seconds": None, "stderr": ""}
    t0 = time.monotonic()
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        row["seconds"] = time.monotonic() - t0
        row["exit"] = proc.returncode
        row["exit_class"] = {0: "ok", 2: "bad_input", 3: "numerics"}.get(proc.returncode, "other")
        row["stderr"] = proc.stderr.strip()
    except subprocess.TimeoutExpired as e:
        row["seconds"] = time.monotonic() - t0
        row["exit_class"] = "timeout"
        err = e.stderr.decode(errors="replace") if isinstance(e.stderr, bytes) else (e.stderr or "")
        row["stderr"] = err.strip()
    except OSError as e:  # could not start it (e.g. the executable was being relinked)
        row["seconds"] = time.monotonic() - t0
        row["exit_class"] = "other"
        row["stderr"] = "could not run %s: %s" % (binary, e)
    report, frf = {}, {}
    try:
        with open(os.path.join(rdir, "run.json")) as f:
            report = json.load(f)
        frf = report.get("frf", {}) or {}
    except (OSError, ValueError):
        pass
    for key in FRF_FIELDS:
        row[key] = frf.get(key)
    # hbm.raise_time_samples: the case's N when a finer one replaced it (None otherwise).
    row["raised_from"] = (frf.get("time_samples_raised") or {}).get("from") if row["exit"] == 0 else None
    # A run that stopped before the continuation (no start found) has no "frf" section:
    # run.json's own status and message say why.
    for key in ("status", "message"):
        if row[key] is None and report.get(key) is not None:
            row[key] = report[key]
    return row


def fmt(v, spec="%.3g"):
    if v is None:
        return "-"
    if isinstance(v, float):
        return "nan" if math.isnan(v) else spec % v
    return str(v)


def failure_message(p, row):
    if row.get("message"):
        return row["message"]
    if row["exit_class"] == "timeout":
        return "timed out"
    lines = [l for l in row.get("stderr", "").splitlines() if l.strip()]
    return lines[-1] if lines else "(no message)"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--count", type=int, default=200, help="models in the corpus (default 200)")
    ap.add_argument("--seed", type=int, default=1, help="corpus seed (default 1)")
    ap.add_argument("--binary", default=os.path.join("build", "src", "app", "shroudsim"),
                    help="shroudsim executable (default build/src/app/shroudsim, relative to the "
                         "working directory, else to the repository)")
    ap.add_argument("--out", default="/tmp/stress", help="case files and results (default /tmp/stress)")
    ap.add_argument("--jobs", type=int, default=2, help="runs in parallel (default 2)")
    ap.add_argument("--timeout", type=float, default=300.0, help="seconds per run (default 300)")
    ap.add_argument("--csv", help="write every row (parameters and results) to this CSV file")
    ap.add_argument("--no-snapshot", action="store_true",
                    help="run --binary in place (default: run a copy taken at the start, OUT/bin/shroudsim, "
                         "so that a rebuild during the benchmark does not mix two programs)")
    ap.add_argument("--keep-results", action="store_true",
                    help="keep the result folders of runs that exit 0 too")
    ap.add_argument("--raw-preload", action="store_true",
                    help="the corpus before 2026-12-05: normal_preload = the drawn load, which the structure "
                         "relaxes at rest (to 1e-4..1 of it), so that 'pressed' draws mostly slip and lift off")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="a case key for every run (repeatable), e.g. response.stability=false to time the "
                         "continuation alone; continuation keys are refused (the corpus runs their defaults)")
    args = ap.parse_args()
    if any(s.startswith("continuation.") for s in args.set):
        ap.error("--set: the corpus runs the default continuation settings")
    if args.count < 1 or args.jobs < 1 or args.timeout <= 0:
        ap.error("--count and --jobs must be >= 1, --timeout > 0")

    binary = args.binary
    if not os.path.isabs(binary) and not os.path.exists(binary) and os.path.exists(os.path.join(ROOT, binary)):
        binary = os.path.join(ROOT, binary)
    binary = os.path.abspath(binary)
    if not os.access(binary, os.X_OK):
        sys.exit("stress_continuation: no executable shroudsim at %s (--binary)" % binary)
    out = os.path.abspath(args.out)
    os.makedirs(os.path.join(out, "cases"), exist_ok=True)
    os.makedirs(os.path.join(out, "runs"), exist_ok=True)
    with open(binary, "rb") as f:
        digest = hashlib.sha256(f.read()).hexdigest()
    built = time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(os.path.getmtime(binary)))
    source_binary = binary
    if not args.no_snapshot:
        os.makedirs(os.path.join(out, "bin"), exist_ok=True)
        binary = os.path.join(out, "bin", "shroudsim")
        shutil.copy2(source_binary, binary)
    try:
        version = subprocess.run([binary, "--version"], capture_output=True, text=True, timeout=30).stdout.strip()
    except (OSError, subprocess.TimeoutExpired) as e:
        sys.exit("stress_continuation: %s does not run (%s); is it being rebuilt?" % (binary, e))

    t_start = time.monotonic()
    models = [draw_model(args.seed, i, args.raw_preload) for i in range(args.count)]
    for p in models:
        with open(os.path.join(out, "cases", p["name"] + ".toml"), "w") as f:
            f.write(p["toml"])
    print("stress_continuation: %d models (seed %d) in %s, %d jobs, timeout %g s" % (
        args.count, args.seed, os.path.join(out, "cases"), args.jobs, args.timeout))
    print("binary: %s, %s (modified %s, sha256 %s)%s" % (version, source_binary, built, digest[:16],
          "" if args.no_snapshot else ", run as the copy " + binary), flush=True)

    rows = [None] * len(models)
    lock = threading.Lock()
    done = [0]

    def work(i):
        row = run_case(models[i], binary, out, args.timeout, args.set)
        with lock:
            done[0] += 1
            print("[%3d/%d] %s %-9s %7.2f s %s" % (done[0], len(models), models[i]["name"], row["exit_class"],
                                                 row["seconds"], fmt(row.get("points"))), file=sys.stderr, flush=True)
        return i, row

    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        for i, row in pool.map(work, range(len(models))):
            rows[i] = row
    wall = time.monotonic() - t_start

    # Table.
    head = ("%-11s %-7s %1s %-17s %-7s %2s %4s %-22s %8s %-9s %-12s %6s %2s %3s %10s %7s"
            % ("case", "model", "n", "structure", "regime", "H", "N", "expect", "r", "exit", "status",
               "points", "pc", "tp", "peak [m]", "sec"))
    print(head)
    print("-" * len(head))
    for p, row in zip(models, rows):
        print("%-11s %-7s %1d %-17s %-7s %2d %4d %-22s %8s %-9s %-12s %6s %2s %3s %10s %7.2f"
              % (p["name"], p["model"], p["n"], p["structure"], p["regime"], p["H"], p["N"], p["expect"],
                 fmt(p["r"]), row["exit_class"], fmt(row.get("status")), fmt(row.get("points")),
                 fmt(row.get("pieces")), fmt(row.get("turning_points")), fmt(row.get("peak_amplitude_m"), "%.3e"),
                 row["seconds"]))

    # Failures.
    failures = [(p, row) for p, row in zip(models, rows) if row["exit_class"] != "ok"]
    print()
    print("Failures (%d):" % len(failures))
    with open(os.path.join(out, "failures.txt"), "w") as f:
        for p, row in failures:
            line = "%s [%s, exit %s] %s | %s | %s" % (
                p["name"], row["exit_class"], fmt(row["exit"]), describe(p), failure_message(p, row),
                os.path.join(out, "cases", p["name"] + ".toml"))
            print("  " + line)
            f.write(line + "\n")
    if not args.keep_results:
        for p, row in zip(models, rows):
            if row["exit_class"] == "ok":
                shutil.rmtree(os.path.join(out, "runs", p["name"]), ignore_errors=True)

    # Summary.
    def count(cls):
        return sum(1 for r in rows if r["exit_class"] == cls)

    def stats(values):
        values = [v for v in values if v is not None]
        if not values:
            return "-"
        return "median %s, max %s" % (fmt(float(statistics.median(values)), "%.4g"), fmt(float(max(values)), "%.4g"))

    ok_rows = [r for r in rows if r["exit_class"] == "ok"]
    two_pieces = sum(1 for r in ok_rows if (r.get("pieces") or 1) > 1)
    print()
    print("Summary (seed %d):" % args.seed)
    print("  reached the end (exit 0): %d of %d (%d of them in two pieces)" % (count("ok"), len(rows), two_pieces))
    raised = [r for r in ok_rows if r.get("raised_from")]
    if raised:
        factors = sorted(set(r["time_samples"] // r["raised_from"] for r in raised))
        print("    of them traced again with a finer N (hbm.raise_time_samples): %d (%s)" % (
            len(raised), ", ".join("%d N: %d" % (k, sum(1 for r in raised if r["time_samples"] // r["raised_from"] == k))
                                   for k in factors)))
    print("  bad input (exit 2, generator bugs): %d" % count("bad_input"))
    print("  numerics failed (exit 3): %d" % count("numerics"))
    # The start search integrates a lumped model in time when the harmonic balance finds no
    # start: its verdict that no motion of the excitation's period exists is in the message.
    def verdict(r):
        m = r.get("message") or ""
        if r["exit_class"] != "numerics" or "time integration: the motion at" not in m:
            return None
        if "nearly periodic" in m:
            return "nearly"
        if "but does with H =" in m:
            return "finer_n"
        for v in ("subharmonic", "not periodic", "periodic"):
            if " is " + v in m:
                return v
        return None
    verdicts = [verdict(r) for r in rows]
    for v, text in (("subharmonic", "subharmonic (repeats every p > 1 periods): no solution of the excitation's "
                                    "period exists"),
                    ("not periodic", "not periodic (changes by more than 1e-2 per period): none exists"),
                    ("nearly", "nearly periodic (changes below 1e-2 per period) but no harmonic-balance "
                               "solution near it"),
                    ("periodic", "periodic, but no harmonic-balance solution near it (H, N given, nor N = 1024 "
                                 "with H or 2H)"),
                    ("finer_n", "periodic, a harmonic-balance solution near it only with N = 1024 (and 2H)")):
        print("    time integration at the failing start: %s: %d" % (text, verdicts.count(v)))
    print("  timeout (> %g s): %d" % (args.timeout, count("timeout")))
    print("  other exit: %d" % count("other"))
    print("  points, all runs with run.json: %s; exit 0: %s" % (stats([r.get("points") for r in rows]),
                                                               stats([r.get("points") for r in ok_rows])))
    print("  seconds, all runs: %s; exit 0: %s" % (stats([r["seconds"] for r in rows]),
                                                   stats([r["seconds"] for r in ok_rows])))
    eb = [r.get("max_energy_balance_error") for r in ok_rows if r.get("max_energy_balance_error") is not None]
    if eb:
        print("  max energy-balance error, exit 0: %.3g" % max(eb))
    print("  total wall time: %.1f s (%d jobs)" % (wall, args.jobs))
    print("  case files: %s/cases/ ; failures: %s" % (out, os.path.join(out, "failures.txt")))

    if args.csv:
        keys = [k for k in models[0] if k != "toml"]
        rkeys = ["exit", "exit_class", "seconds"] + FRF_FIELDS + ["raised_from"]
        with open(args.csv, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(keys + rkeys + ["case_file"])
            for p, row in zip(models, rows):
                w.writerow([p[k] for k in keys] + [row.get(k) for k in rkeys] +
                           [os.path.join(out, "cases", p["name"] + ".toml")])
    return 0


if __name__ == "__main__":
    sys.exit(main())
