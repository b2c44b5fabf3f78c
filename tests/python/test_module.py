"""The Python module (src/python, docs/python.md) against the command line.

Run by ctest (tests/python/CMakeLists.txt) with PYTHONPATH at the module's build folder and
SHROUDSIM_EXE, SHROUDSIM_SOURCE_DIR, SHROUDSIM_BUILD_DIR, SHROUDSIM_PYTHON_INSTALL_DIR set;
one test class per ctest test:

    python3 tests/python/test_module.py -v LumpedForcedResponse

Each test works in its own scratch folder (the generated meshes go to meshes/ of the working
directory, the modal cache beside the case file), so the command line and the module each
compute from scratch.
"""
import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile
import tomllib
import unittest

import numpy as np

import shroudsim

SOURCE = os.environ.get("SHROUDSIM_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
EXE = os.environ.get("SHROUDSIM_EXE", os.path.join(SOURCE, "build", "src", "app", "shroudsim"))
LUMPED = os.path.join(SOURCE, "cases", "lumped_jenkins.toml")
WHEEL = os.path.join(SOURCE, "cases", "shrouded_wheel.toml")
# The default case on a coarse mesh with fewer modes and harmonics, as the command line's
# own test of it (tests/app/test_cli_shroud.cpp, TheDefaultCaseIsAWheelAtSpeedThatRunsEndToEnd).
COARSE_WHEEL = {
    "geometry.element_order": 1,
    "geometry.mesh_size": 0.017,
    "modal.modes": 6,
    "hbm.harmonics": 3,
    "hbm.time_samples": 128,
    "campbell.speed_points": 4,
}


def read_text(path):
    with open(path) as f:
        return f.read()


def read_json(path):
    return json.loads(read_text(path))


def set_args(overrides):
    args = []
    for key, value in overrides.items():
        args += ["--set", f"{key}={value}"]
    return args


def read_csv(path):
    """{column: float64 array} of a numeric CSV file, read independently of the module."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return {name: np.array([float(r[i]) for r in rows[1:]]) for i, name in enumerate(rows[0])}


class Scratch:
    """A scratch folder as working directory for the duration of a test."""

    def __init__(self, test):
        self.dir = tempfile.mkdtemp(prefix="shroudsim_python_")
        cwd = os.getcwd()
        os.chdir(self.dir)
        test.addCleanup(shutil.rmtree, self.dir, True)
        test.addCleanup(os.chdir, cwd)

    def folder(self, name, *files):
        """A subfolder holding copies of `files` (a case with its own modal cache)."""
        path = os.path.join(self.dir, name)
        os.makedirs(path)
        for f in files:
            shutil.copy(f, path)
        return path


def run_cli(*args, cwd=None):
    r = subprocess.run([EXE, *args], cwd=cwd, capture_output=True, text=True)
    return r.returncode, r.stderr


class Agreement:
    """Largest absolute and relative difference of the common columns of two tables."""

    def __init__(self, expected, actual, columns):
        self.abs = self.rel = 0.0
        for c in columns:
            a, b = np.asarray(expected[c], float), np.asarray(actual[c], float)
            assert a.shape == b.shape, (c, a.shape, b.shape)
            d = np.abs(a - b)
            self.abs = max(self.abs, float(d.max(initial=0.0)))
            scale = np.maximum(np.abs(a), np.finfo(float).tiny)
            self.rel = max(self.rel, float((d / scale).max(initial=0.0)))

    def __str__(self):
        return f"max abs difference {self.abs:.3g}, max rel difference {self.rel:.3g}"


def assert_same_frf(test, cli_dir, result, label):
    """The module's curve, peaks and loops against the files the command line wrote."""
    expected = read_csv(os.path.join(cli_dir, "frf.csv"))
    test.assertEqual(list(expected), list(result.columns), "frf.csv columns")
    test.assertGreater(len(result.frequency_hz), 10)
    frf = Agreement(expected, result.columns, expected)
    peaks = Agreement(read_csv(os.path.join(cli_dir, "peaks.csv")), result.peaks, ["frequency_hz", "amplitude_m"])
    loops = read_csv(os.path.join(cli_dir, "loops.csv"))
    n = result.loop_displacement_m.shape
    loop = Agreement(
        {"x": loops["x_m"], "f": loops["n_n"]},
        {"x": result.loop_displacement_m[:, :, 0].ravel(), "f": result.loop_force_n[:, :, 2].ravel()},
        ["x", "f"],
    )
    print(f"{label}: {len(result.frequency_hz)} points, {n[0]} loops: frf.csv {frf}; peaks.csv {peaks}; "
          f"loops.csv {loop}", file=sys.stderr)
    # The same library calls on the same inputs: the same doubles (round-off would show as a
    # relative difference of ~1e-15; the files are written at round-trip precision).
    for what, a in (("frf.csv", frf), ("peaks.csv", peaks), ("loops.csv", loop)):
        test.assertLessEqual(a.rel, 1e-12, f"{what}: {a}")
    cli_run = read_json(os.path.join(cli_dir, "run.json"))
    test.assertEqual(result.report["frf"]["points"], cli_run["frf"]["points"])
    test.assertEqual(result.peak_amplitude_m, cli_run["frf"]["peak_amplitude_m"])
    test.assertEqual(result.report["status"], cli_run["status"])


class LumpedForcedResponse(unittest.TestCase):
    """cases/lumped_jenkins.toml from Python: the command line's numbers, from a file or a dict."""

    def test_the_curve_is_the_command_lines(self):
        s = Scratch(self)
        status, err = run_cli("frf", LUMPED, "--out", "cli", "--quiet", "--threads", "1")
        self.assertEqual(status, 0, err)
        case = shroudsim.Case(LUMPED)
        self.assertEqual(case.structure_type, "lumped")
        r = case.frf(out="py", threads=1, quiet=True)
        self.assertEqual(r.status, "ok")
        self.assertEqual(r.out, os.path.join(s.dir, "py"))
        assert_same_frf(self, "cli", r, "lumped")
        # The results folder is the command line's: the same files, frf.csv byte for byte.
        for f in ("frf.csv", "peaks.csv", "loops.csv", "run.json"):
            self.assertTrue(os.path.exists(os.path.join("py", f)), f)
        self.assertEqual(read_text("py/frf.csv"), read_text("cli/frf.csv"))
        self.assertEqual(read_json("py/run.json")["driver"], "python")
        np.testing.assert_array_equal(r.harmonic_amplitudes_m[:, 1], r.columns["h1_m"])
        self.assertEqual(r.loop_force_n.shape, (1, 256, 3))
        self.assertEqual(r.report["case"]["hbm"]["harmonics"], 5)

    def test_a_dict_case_with_overrides_is_the_file_with_set(self):
        s = Scratch(self)
        status, err = run_cli("frf", LUMPED, "--out", "cli", "--quiet", "--threads", "1", "--set", "hbm.harmonics=3",
                              "--set", "contact.friction_coefficient=0.2")
        self.assertEqual(status, 0, err)
        with open(LUMPED, "rb") as f:
            as_dict = tomllib.load(f)
        case = shroudsim.Case.from_dict(as_dict, {"hbm.harmonics": 3, "contact.friction_coefficient": 0.2})
        self.assertEqual(case.file, os.path.join(s.dir, "<dict>"))
        self.assertIn("[[3947.8417604357433]]", case.source)
        self.assertEqual(case.to_dict()["contact"]["friction_coefficient"], 0.2)
        assert_same_frf(self, "cli", case.frf(threads=1, quiet=True), "lumped from a dict")
        # with_overrides on the file case: the same case as the dict's.
        again = shroudsim.load_case(LUMPED).with_overrides(["hbm.harmonics=3", "contact.friction_coefficient=0.2"])
        self.assertEqual(again.to_dict(), case.to_dict())
        self.assertEqual(again.overrides, ["hbm.harmonics=3", "contact.friction_coefficient=0.2"])


class SectorForcedResponse(unittest.TestCase):
    """The default case (cases/shrouded_wheel.toml) on a coarse mesh: forced response, modes,
    Campbell diagram, static contact, mesh."""

    def test_the_default_sector_gives_the_command_lines_numbers(self):
        s = Scratch(self)
        cli_case = os.path.join(s.folder("cli_case", WHEEL), "shrouded_wheel.toml")
        py_case = os.path.join(s.folder("py_case", WHEEL), "shrouded_wheel.toml")
        status, err = run_cli("frf", cli_case, "--out", "cli", "--quiet", "--threads", "2", *set_args(COARSE_WHEEL),
                              "--set", "response.shapes_at_hz=[190.0, 300.0]")
        self.assertEqual(status, 0, err)
        self.check_shapes("cli", err)
        case = shroudsim.Case(py_case, COARSE_WHEEL)
        r = case.frf(threads=2, quiet=True)
        self.assertEqual(r.report["frf_model"]["normal_preload_from"], "static")
        self.assertTrue(r.report["frf"]["energy_check_passed"])
        self.assertEqual(r.loop_displacement_m.shape, (5, 128, 3))
        assert_same_frf(self, "cli", r, "default sector (coarse)")

        # Modes: the command line's modes.csv; the shapes on every node of the sector.
        status, err = run_cli("modes", cli_case, "--out", "cli_modes", "--quiet", "--threads", "2",
                              *set_args(COARSE_WHEEL))
        self.assertEqual(status, 0, err)
        m = case.modes(shapes=True, threads=2, quiet=True)
        expected = read_csv("cli_modes/modes.csv")
        got = np.concatenate([m.frequencies_hz[h] for h in m.harmonic_indices])
        agreement = Agreement({"f": expected["frequency_hz"]}, {"f": got}, ["f"])
        print(f"modes: {len(got)} frequencies: {agreement}", file=sys.stderr)
        self.assertLessEqual(agreement.rel, 1e-12, str(agreement))
        self.assertEqual(list(m.harmonic_indices), list(range(36)))
        self.assertEqual(m.nodal_diameters[35], 1)
        shape = m.shapes[4]
        self.assertEqual(shape.shape, (6, len(m.nodes), 3))
        self.assertTrue(np.all(np.isfinite(shape)))
        self.assertGreater(np.abs(shape).max(), 0.0)
        # Campbell diagram and static contact: the command line's tables.
        status, err = run_cli("campbell", cli_case, "--out", "cli_campbell", "--quiet", "--threads", "2",
                              *set_args(COARSE_WHEEL))
        self.assertEqual(status, 0, err)
        cb = case.campbell(threads=2, quiet=True)
        for table in ("campbell", "crossings"):
            expected = read_csv(f"cli_campbell/{table}.csv")
            agreement = Agreement(expected, getattr(cb, table), expected)
            print(f"{table}.csv: {len(expected['frequency_hz'])} rows: {agreement}", file=sys.stderr)
            self.assertLessEqual(agreement.rel, 1e-12, f"{table}: {agreement}")
        st = case.static_contact(threads=2, quiet=True)
        self.assertEqual(len(st.pairs["state"]), st.summary["open"] + st.summary["stick"] + st.summary["slip"])
        self.assertTrue(set(st.pairs["state"]) <= {"open", "stick", "slip"})
        mesh = case.mesh(quiet=True)
        self.assertEqual(mesh.nodes.shape, m.nodes.shape)
        self.assertEqual(mesh.elements.shape[1], 4)
        self.assertEqual(len(mesh.shroud_pairs), mesh.report["mesh"]["shroud_pairs"])


    def check_shapes(self, out, err):
        """frf.vtu, contact.vtu, the frame series and contact_map.csv of a sector forced
        response, opened in their readers: fields, sizes, finite values, and the shape at the
        response node is the curve's amplitude."""
        report = json.loads(read_text(os.path.join(out, "run.json")))
        shapes = report["shapes"]
        names = [sh["name"] for sh in shapes]
        self.assertIn("peak1", names)
        self.assertIn("f190hz", names)  # 300 Hz lies outside the range: a warning, no shape
        self.assertIn("does not reach 300 Hz", err)
        counts = {"shapes": len(shapes)}
        try:
            import meshio
        except ImportError:
            self.skipTest("meshio is not installed")
        frf = meshio.read(os.path.join(out, "frf.vtu"))
        n = len(frf.points)
        harmonics = COARSE_WHEEL["hbm.harmonics"]
        node = report["frf_model"]["response_node"]
        for sh in shapes:
            for k in range(harmonics + 1):
                for part in ("re", "im"):
                    field = frf.point_data[f"{sh['name']}_u_h{k}_{part}_m"]
                    self.assertEqual(field.shape, (n, 3))
                    self.assertTrue(np.all(np.isfinite(field)))
            amplitude = frf.point_data[f"{sh['name']}_amplitude_m"].reshape(-1)
            self.assertEqual(amplitude.shape, (n,))
            # max_t |u(t)| over 512 samples against the curve's sampled-and-refined maximum:
            # (pi/512)^2/2 = 2e-5 for a first-harmonic motion, up to 5e-4 with H = 3 to 5
            # harmonics; the field is stored in single precision (6e-8).
            self.assertAlmostEqual(amplitude[node] / sh["amplitude_m"], 1.0, delta=5e-4)
            self.assertGreater(amplitude.max(), 0.0)
        # The largest peak's time series: frf.pvd lists 24 frames that exist and hold the shape.
        pvd = read_text(os.path.join(out, "frf.pvd"))
        frames = [line.split('file="')[1].split('"')[0] for line in pvd.splitlines() if "file=" in line]
        self.assertEqual(len(frames), 24)
        frame = meshio.read(os.path.join(out, frames[6]))
        self.assertEqual(frame.point_data["displacement_m"].shape, (n, 3))
        self.assertTrue(np.all(np.isfinite(frame.point_data["displacement_m"])))
        # The contact map: on the face nodes, fractions that add up to one.
        contact = meshio.read(os.path.join(out, "contact.vtu"))
        on_face = contact.point_data["contact_pair"].reshape(-1) >= 0
        pairs = report["frf_model"]["contact_pairs"]
        self.assertGreaterEqual(on_face.sum(), 2 * pairs)
        with open(os.path.join(out, "contact_map.csv"), newline="") as f:
            rows = list(csv.DictReader(f))
        self.assertEqual(len(rows), pairs * len(shapes))
        column = lambda name, shape=None: np.array([float(r[name]) for r in rows if shape in (None, r["shape"])])
        total = column("stick_fraction") + column("slip_fraction") + column("open_fraction")
        np.testing.assert_allclose(total, 1.0, atol=1e-12)
        self.assertTrue(np.all(column("energy_per_cycle_j") >= -1e-12))
        energy = contact.point_data["peak1_energy_per_cycle_j"].reshape(-1)
        self.assertTrue(np.all(np.isfinite(energy)))
        self.assertEqual(energy[~on_face].max(), 0.0)
        peak_energy = column("energy_per_cycle_j", "peak1")
        self.assertAlmostEqual(energy[on_face].max(), peak_energy.max(), delta=1e-6 * peak_energy.max())
        # The pairs' energies add up to the contact dissipation of the curve's energy balance
        # at the peak: positive, as friction only dissipates.
        self.assertGreater(peak_energy.sum(), 0.0)
        counts.update(nodes=n, face_nodes=int(on_face.sum()), pairs=pairs)
        print(f"shapes: {counts}", file=sys.stderr)


class Errors(unittest.TestCase):
    """Bad input raises shroudsim.InputError with file, line and key; failed numerics raise
    shroudsim.NumericalError with what was computed."""

    def assert_input_error(self, call, file, line, key, cli_args=None):
        with self.assertRaises(shroudsim.InputError) as raised:
            call()
        e = raised.exception
        self.assertIsInstance(e, shroudsim.Error)
        self.assertEqual((e.file, e.line, e.key), (file, line, key), str(e))
        if cli_args:  # the message the command line prints
            status, err = run_cli(*cli_args)
            self.assertEqual(status, 2)
            self.assertEqual(err, f"shroudsim: error: {e}\n")
        return e

    def test_bad_case_files_name_file_line_and_key(self):
        s = Scratch(self)
        case = os.path.join(s.dir, "case.toml")
        with open(case, "w") as f:
            f.write('name = "bad"\n[structure]\ntype = "lumped"\nmass = [[1.0]]\nstiffness = [[1.0]]\n'
                    "[hbm]\nharmonics = 2.5\n")
        e = self.assert_input_error(lambda: shroudsim.Case(case), case, 7, "hbm.harmonics",
                                    ["frf", case, "--quiet"])
        self.assertIn("expected an integer", str(e))
        self.assertEqual(e.column, 13)
        # A misspelt key, a missing key (no line: it is not there), an override.
        with open(case, "w") as f:
            f.write('[geometry]\nmesh_sise = 0.02\n')
        e = self.assert_input_error(lambda: shroudsim.Case(case), case, 2, "geometry.mesh_sise",
                                    ["mesh", case, "--quiet"])
        self.assertIn("did you mean 'geometry.mesh_size'", str(e))
        with open(case, "w") as f:
            f.write('[structure]\ntype = "lumped"\nstiffness = [[1.0]]\n')
        self.assert_input_error(lambda: shroudsim.Case(case), case, None, "structure.mass", ["frf", case, "--quiet"])
        self.assert_input_error(lambda: shroudsim.Case(LUMPED, {"hbm.harmonics": 0}), LUMPED, None, "hbm.harmonics",
                                ["frf", LUMPED, "--quiet", "--set", "hbm.harmonics=0"])
        self.assert_input_error(lambda: shroudsim.Case(os.path.join(s.dir, "missing.toml")),
                                os.path.join(s.dir, "missing.toml"), None, None)

    def test_bad_dict_cases_raise_too(self):
        s = Scratch(self)
        with open(LUMPED, "rb") as f:
            good = tomllib.load(f)
        dict_file = os.path.join(s.dir, "<dict>")
        # The line of a key is its line in the TOML text the dict becomes (Case.source).
        line = shroudsim.Case.from_dict(good).source.splitlines().index("harmonics = 5") + 1
        bad = good | {"hbm": good["hbm"] | {"harmonics": -1}}
        e = self.assert_input_error(lambda: shroudsim.Case.from_dict(bad), dict_file, line, "hbm.harmonics")
        self.assertIn("hbm.harmonics = -1 violates", str(e))
        wrong_type = good | {"hbm": good["hbm"] | {"harmonics": "five"}}
        self.assert_input_error(lambda: shroudsim.Case.from_dict(wrong_type), dict_file, line, "hbm.harmonics")
        self.assert_input_error(lambda: shroudsim.Case.from_dict(good | {"hbm": {"harmonics": None}}), dict_file,
                                None, "hbm.harmonics")
        self.assert_input_error(lambda: shroudsim.Case.from_dict(good, {"contact.mu": 0.2}), dict_file, None,
                                "contact.mu")

    def test_errors_of_a_stage(self):
        s = Scratch(self)
        lumped = shroudsim.Case(LUMPED)
        # `modes` of a lumped case: the position of structure.type in the case file.
        self.assert_input_error(lambda: lumped.modes(quiet=True), LUMPED, 6, "structure.type",
                                ["modes", LUMPED, "--quiet", "--out", "x"])
        # Bad input leaves the results folder untouched.
        os.makedirs("out")
        with open("out/run.json", "w") as f:
            f.write("{}")
        zero = lumped.with_overrides({"excitation.force": 0.0})
        self.assert_input_error(lambda: zero.frf(out="out", quiet=True), LUMPED, None, "excitation.force")
        self.assertEqual(os.listdir("out"), ["run.json"])
        # The continuation stopped by max_points: NumericalError, the points in `out` and in e.result.
        short = lumped.with_overrides({"continuation.max_points": 5})
        with self.assertRaises(shroudsim.NumericalError) as raised:
            short.frf(out="out", quiet=True)
        e = raised.exception
        self.assertIn("continuation stopped", str(e))
        self.assertEqual(e.result.status, "numerics_failed")
        self.assertEqual(len(e.result.frequency_hz), 5)
        self.assertEqual(read_json("out/run.json")["status"], "numerics_failed")
        status, err = run_cli("frf", LUMPED, "--quiet", "--out", "cli", "--set", "continuation.max_points=5")
        self.assertEqual((status, err), (3, f"shroudsim: numerics failed: {e}\n"))
        # Options the module checks itself.
        with self.assertRaises(ValueError):
            lumped.frf(plots=True)
        with self.assertRaises(TypeError):
            lumped.frf("out")  # keyword-only


class InstalledModule(unittest.TestCase):
    """`cmake --install` puts the module where Debian's python3 finds it from the prefix, and
    the example beside the case files; the installed example runs with the installed module."""

    def test_the_installed_example_runs_with_the_installed_module(self):
        build = os.environ["SHROUDSIM_BUILD_DIR"]
        prefix = tempfile.mkdtemp(prefix="shroudsim_prefix_")
        self.addCleanup(shutil.rmtree, prefix, True)
        subprocess.run(["cmake", "--install", build, "--prefix", prefix], check=True, capture_output=True)
        site = os.path.join(prefix, os.environ["SHROUDSIM_PYTHON_INSTALL_DIR"])
        env = dict(os.environ, PYTHONPATH=site)
        r = subprocess.run([sys.executable, "-c", "import shroudsim; print(shroudsim.__file__)"], env=env,
                           capture_output=True, text=True, cwd=prefix)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertTrue(r.stdout.startswith(site), r.stdout)
        example = os.path.join(prefix, "share", "shroudsim", "examples", "python_forced_response.py")
        png = os.path.join(prefix, "frf.png")
        r = subprocess.run([sys.executable, example, png], env=env, capture_output=True, text=True, cwd=prefix)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("peak: ", r.stdout)
        self.assertGreater(os.path.getsize(png), 10000)


if __name__ == "__main__":
    unittest.main()
