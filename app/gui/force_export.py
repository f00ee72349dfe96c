"""The force plot's exports: the forces CSV (app/model/readouts.py `forces_table`: every model's
drag, lift and coefficients, the probes' columns joined on the step, SI columns where the units
shown are SI) and the plot as a PNG (pyqtgraph's exporter), both written atomically
(app/files.py)."""
from __future__ import annotations

import pyqtgraph.exporters

from feelflow.app.files import atomic_path, write_text_atomic
from feelflow.app.model import readouts
from feelflow.app.model.simulation import FORCE_MODELS


class ForceExport:
    """`probes`: the window's probes (app.model.probes.Probes), whose columns join the CSV."""

    def __init__(self):
        self.probes = None

    def csv_text(self, sim, units) -> str:
        return readouts.forces_table(sim.history, FORCE_MODELS, sim.reference_length(), self.probes, units)

    def write_csv(self, path, sim, units):
        write_text_atomic(path, self.csv_text(sim, units))

    @staticmethod
    def write_png(path, plot_item):
        exporter = pyqtgraph.exporters.ImageExporter(plot_item)
        with atomic_path(path, suffix=".png") as tmp:
            exporter.export(str(tmp))
