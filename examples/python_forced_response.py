# %% [markdown]
# # The forced response of a friction-damped oscillator from Python
#
# The lumped case `cases/lumped_jenkins.toml` (a 10 Hz, 1 % damped oscillator with a Jenkins
# friction element to ground), run through the `shroudsim` Python module (docs/python.md):
# the curve as numpy arrays, the located peak, and the same case at other normal preloads,
# drawn with matplotlib. The cells (`# %%`) run one by one in VS Code or Jupyter (jupytext),
# or all at once:
#
#     PYTHONPATH=build/src/python python3 examples/python_forced_response.py [OUT.png]
#
# (The installed module needs no PYTHONPATH: docs/python.md.)

# %% Imports and the case file (beside this script once installed, in cases/ in the source tree)
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # draw into a file; remove in a notebook to see the figure inline
import matplotlib.pyplot as plt

import shroudsim

here = Path(__file__).resolve().parent if "__file__" in globals() else Path.cwd()
case_file = next(p for p in (here / "lumped_jenkins.toml", here.parent / "cases" / "lumped_jenkins.toml")
                 if p.exists())
png = Path(sys.argv[1]) if len(sys.argv) > 1 and not sys.argv[1].startswith("-") else Path(
    "python_forced_response.png")

# %% Load the case; overrides use the command line's --set keys
case = shroudsim.Case(case_file, {"hbm.harmonics": 5})
print(case)

# %% Run the forced response (`shroudsim frf`): the curve, its peaks and the run statistics
frf = case.frf(quiet=True)  # out="results/lumped" would also write the command line's files
print(f"{len(frf.frequency_hz)} points, {frf.report['frf']['newton_iterations']} Newton iterations, "
      f"{frf.report['total_seconds']:.2f} s")

# %% The located resonance peak
print(f"peak: {frf.peak_amplitude_m * 1e3:.4f} mm at {frf.peak_frequency_hz:.4f} Hz")

# %% The same oscillator at other normal preloads: more preload, more stick, a stiffer peak
curves = {}
for preload in (0.25, 1.0, 4.0):
    r = case.with_overrides({"contact.normal_preload": preload}).frf(quiet=True)
    curves[preload] = r

# %% Plot the curves (amplitude in mm against frequency) with the linear response and the peaks
fig, ax = plt.subplots(figsize=(7, 4.5), layout="constrained")
ax.plot(frf.frequency_hz, frf.linear_amplitude_m * 1e3, color="0.6", ls="--", lw=1, label="no contact (free)")
for preload, r in curves.items():
    line, = ax.plot(r.frequency_hz, r.amplitude_m * 1e3, lw=1.5, label=f"normal preload {preload:g} N")
    ax.plot(r.peaks["frequency_hz"], r.peaks["amplitude_m"] * 1e3, "o", color=line.get_color(), ms=5)
ax.annotate(f"{frf.peak_amplitude_m * 1e3:.3f} mm\n{frf.peak_frequency_hz:.3f} Hz",
            (frf.peak_frequency_hz, frf.peak_amplitude_m * 1e3), textcoords="offset points", xytext=(12, 4))
ax.set_xlabel("excitation frequency [Hz]")
ax.set_ylabel("response amplitude [mm]")
ax.set_title(f"{case.name}: forced response (harmonic balance, H = {case.to_dict()['hbm']['harmonics']})")
ax.set_yscale("log")
ax.grid(True, which="both", alpha=0.3)
ax.legend()
fig.savefig(png, dpi=120)
print(f"wrote {png}")
