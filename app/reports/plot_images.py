"""Report plots as PNG images: pyqtgraph set up offscreen (white background), and a widget's
picture written atomically through app/files.py. Shared by the seed report and the polar."""
from __future__ import annotations

import os
from pathlib import Path


def offscreen_pyqtgraph():
    """pyqtgraph with a QApplication, offscreen where there is no display, drawing black on white."""
    if "QT_QPA_PLATFORM" not in os.environ and not os.environ.get("DISPLAY"):
        os.environ["QT_QPA_PLATFORM"] = "offscreen"
    import pyqtgraph as pg

    pg.mkQApp()
    pg.setConfigOptions(background="w", foreground="k", antialias=True)
    return pg


def export_png(widget, item, path: Path, width: int = 900) -> None:
    """Write `item` (a plot item or a whole scene of `widget`) as PNG atomically, then dispose of
    the widget (Qt objects left for the interpreter's shutdown can crash PySide6 there)."""
    from pyqtgraph.exporters import ImageExporter
    from pyqtgraph.Qt import QtWidgets

    from feelflow.app.files import atomic_path

    widget.show()  # lay the plot out (title, axes) before rendering it
    QtWidgets.QApplication.processEvents()
    try:
        with atomic_path(path, suffix=".png") as tmp:
            exporter = ImageExporter(item)
            exporter.parameters()["width"] = width
            exporter.export(str(tmp))
    finally:
        widget.close()
        widget.deleteLater()
        QtWidgets.QApplication.processEvents()
