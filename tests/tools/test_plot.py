"""tools/plot.py as shroudsim runs it: `--wait` (started with the command, arguments on stdin
when the results are there), an empty stdin (the command drew nothing: exit 0, no file), and
exit 3 without matplotlib (shroudsim then says the plots were skipped)."""
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PLOT = os.path.join(ROOT, "tools", "plot.py")

MODES_CSV = """harmonic_index,nodal_diameter,mode,frequency_hz
0,0,1,100.0
0,0,2,250.0
1,1,1,101.0
1,1,2,260.0
"""


def have_matplotlib():
    return subprocess.run([sys.executable, "-c", "import matplotlib"], capture_output=True).returncode == 0


@unittest.skipUnless(have_matplotlib(), "needs matplotlib")
class WaitingPlotter(unittest.TestCase):
    def test_arguments_on_stdin_draw_the_plots(self):
        with tempfile.TemporaryDirectory() as d:
            with open(os.path.join(d, "modes.csv"), "w") as f:
                f.write(MODES_CSV)
            r = subprocess.run([sys.executable, PLOT, "--wait"], input=f"{d}\n--shroud\nopen\n", text=True,
                               capture_output=True, timeout=120)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertTrue(os.path.exists(os.path.join(d, "nd_map.png")))

    def test_nd_map_has_a_second_panel_only_beyond_ten_families(self):
        # The PNG's width (bytes 16-19 of its header) tells one panel (7.5 in at 120 dpi) from two
        # (13 in); both have the legend's 1.3 in beside them.
        for families, width in ((2, 1056), (10, 1056), (12, 1716)):
            with tempfile.TemporaryDirectory() as d:
                with open(os.path.join(d, "modes.csv"), "w") as f:
                    f.write("harmonic_index,nodal_diameter,mode,frequency_hz\n")
                    for h in (0, 1):
                        for m in range(1, families + 1):
                            f.write(f"{h},{h},{m},{100.0 * m + h}\n")
                r = subprocess.run([sys.executable, PLOT, d], capture_output=True, text=True, timeout=120)
                self.assertEqual(r.returncode, 0, r.stderr)
                with open(os.path.join(d, "nd_map.png"), "rb") as f:
                    self.assertEqual(int.from_bytes(f.read(24)[16:20], "big"), width, families)

    def test_empty_stdin_draws_nothing(self):
        with tempfile.TemporaryDirectory() as d:
            with open(os.path.join(d, "modes.csv"), "w") as f:
                f.write(MODES_CSV)
            r = subprocess.run([sys.executable, PLOT, "--wait"], input="", text=True, capture_output=True,
                               timeout=120)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertFalse(os.path.exists(os.path.join(d, "nd_map.png")))


class WithoutMatplotlib(unittest.TestCase):
    def test_exit_status_three_and_silence(self):
        # A module named matplotlib that fails to import stands in for a missing one.
        with tempfile.TemporaryDirectory() as d:
            with open(os.path.join(d, "matplotlib.py"), "w") as f:
                f.write("raise ImportError('no matplotlib here')\n")
            env = dict(os.environ, PYTHONPATH=d)
            for args, stdin in (([d], ""), (["--wait"], f"{d}\n")):
                r = subprocess.run([sys.executable, PLOT] + args, input=stdin, text=True, capture_output=True,
                                   env=env, timeout=120)
                self.assertEqual(r.returncode, 3, (args, r.stderr))
                self.assertEqual(r.stderr, "", args)


if __name__ == "__main__":
    unittest.main()
