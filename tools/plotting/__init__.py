"""Plotters of shroudsim's result files (tools/plot.py dispatches to them)."""
import csv
import os
import re


def result_name(result_dir):
    """The result folder's name for plot titles. Results are written into a staging folder
    `.<name>.staging-<pid>` that is renamed to `<name>` when the run ends (docs/contract.md),
    so the staging part is removed."""
    name = os.path.basename(os.path.normpath(result_dir))
    m = re.fullmatch(r"\.(.+)\.staging-\d+", name)
    return m.group(1) if m else name


def read_csv(path):
    """The rows of a result CSV file as dicts keyed by its header."""
    with open(path, newline="") as f:
        return list(csv.DictReader(f))
