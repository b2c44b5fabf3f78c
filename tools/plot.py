#!/usr/bin/python3
"""Plots of a shroudsim result folder (matplotlib).

usage: tools/plot.py RESULT_DIR [--shroud open|stuck|contact]
       tools/plot.py --wait      (the same arguments, one per line, on stdin: see below)

--shroud names the shroud state of the modal model in the titles of nd_map.png and
campbell.png (modal.shroud of the case).

Draws whatever the folder holds results for:
  modes.csv            -> nd_map.png        (frequency against nodal diameter)
  campbell.csv         -> campbell.png      (frequency against speed, engine orders, crossings)
  static_contact.csv   -> contact_static.png (static shroud contact pressure and state over the face)
  contact.json         -> contact_loops.png (hysteresis loops of one contact pair)
  frf.csv              -> frf.png           (nonlinear and linear forced response)
  loops.csv            -> loops.png         (contact loops at the peak)
  nlmodes.csv          -> nlmodes.png       (nonlinear mode: frequency and damping against amplitude,
                                             and the forced responses synthesized from it)
  contact_map.csv      -> contact.png       (energy, stick/slip/open of each pair at each shape)
  frf.vtu              -> shape.png         (the largest peak's deflection shape; needs meshio)
  study.csv            -> study.png         (peak amplitude and frequency over a sweep)
  trade.csv            -> trade.png         (error against cost per knob, study --convergence)
Exits 0 when it drew everything it found, 1 on a plotting failure, 2 on bad usage, 3 (silently)
when matplotlib is not installed: shroudsim then reports the plots as skipped.
"""
import importlib
import os
import sys

# Plots need no BLAS threads: OpenBLAS (loaded with numpy) otherwise starts one per core,
# a tenth of a second of system time at import.
os.environ["OPENBLAS_NUM_THREADS"] = "1"

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

# (result file, module in tools/plotting, function)
PLOTS = [
    ("modes.csv", "plotting.modal_plots", "plot_nd_map"),
    ("campbell.csv", "plotting.modal_plots", "plot_campbell"),
    ("static_contact.csv", "plotting.modal_plots", "plot_static_contact"),
    ("contact.json", "plotting.contact_plots", "plot_contact"),
    ("frf.csv", "plotting.frf_plots", "plot_frf"),
    ("nlmodes.csv", "plotting.nlmodes_plots", "plot_nlmodes"),
    ("contact_map.csv", "plotting.contact_plots", "plot_contact_map"),
    ("frf.vtu", "plotting.shape_plots", "plot_shape"),
    ("study.csv", "plotting.study_plots", "plot_study"),
    ("trade.csv", "plotting.study_plots", "plot_trade"),
]


NO_MATPLOTLIB = 3


def warm_up():
    """Loads what the first drawing would load on demand (the font, the Agg renderer, the PNG
    writer) by drawing a small figure into memory."""
    import io

    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(1, 1))
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    ax.plot([0, 1], [0, 1], "o-", label="x")
    ax.set_xlabel("x")
    ax.legend(fontsize=7)
    fig.savefig(io.BytesIO(), format="png", dpi=20)


def wait_for_arguments():
    """`plot.py --wait`: shroudsim starts the plotter with its command, so that Python and
    matplotlib load while it computes, and writes the arguments (one per line) to its stdin
    when the results are there. Empty stdin: the command drew no plots; nothing to do."""
    try:
        import matplotlib  # noqa: F401 (loaded now: the point of waiting)
        matplotlib.use("Agg")
        import matplotlib.pyplot  # noqa: F401
    except ImportError:
        sys.stdin.read()
        return None, NO_MATPLOTLIB
    try:
        warm_up()
    except Exception:  # noqa: BLE001 (only a head start: the plots report their own failures)
        pass
    args = [line.rstrip("\n") for line in sys.stdin]
    return args, 0


def main(argv):
    args = argv[1:]
    if args == ["--wait"]:
        args, status = wait_for_arguments()
        if args is None or not args:
            return status
    shroud = None
    if len(args) == 3 and args[1] == "--shroud" and args[2] in ("open", "stuck", "contact"):
        shroud = args[2]
        args = args[:1]
    if len(args) != 1 or args[0] in ("-h", "--help"):
        print(__doc__, file=sys.stderr)
        return 2
    result_dir = args[0]
    if shroud:
        os.environ["SHROUDSIM_PLOT_SHROUD"] = shroud
    if not os.path.isdir(result_dir):
        print(f"plot.py: {result_dir}: no such result folder", file=sys.stderr)
        return 2
    try:
        import matplotlib
    except ImportError:
        return NO_MATPLOTLIB
    matplotlib.use("Agg")
    status = 0
    for filename, module, function in PLOTS:
        if not os.path.exists(os.path.join(result_dir, filename)):
            continue
        try:
            getattr(importlib.import_module(module), function)(result_dir)
        except ModuleNotFoundError as e:  # an incomplete installation
            print(f"plot.py: {filename}: the plotting module is missing ({e})", file=sys.stderr)
            status = 1
        except Exception as e:  # a broken plot must not hide the others
            print(f"plot.py: {filename}: {e}", file=sys.stderr)
            status = 1
    return status


if __name__ == "__main__":
    status = main(sys.argv)
    # The plots are written: leave without the interpreter's teardown of matplotlib and numpy
    # (up to 0.15 s that shroudsim would wait for).
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(status)
