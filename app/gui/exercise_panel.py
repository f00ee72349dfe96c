"""The exercise panel beside the flow: goal and instructions, the shape's parameters (for
exercises on a built-in body), the constraints as they stand, Score it with progress and
Cancel, the result against the reference solutions, and the attempts with thumbnails.

Widgets only; app/gui/exercise_controller.py connects them to the tunnel and the scoring."""
from __future__ import annotations

import math

from PySide6.QtCore import QPointF, QSize, Qt, Signal
from PySide6.QtGui import QColor, QIcon, QPainter, QPen, QPixmap, QPolygonF
from PySide6.QtWidgets import (QComboBox, QDoubleSpinBox, QFormLayout, QGroupBox, QHBoxLayout, QLabel, QListWidget,
                               QListWidgetItem, QProgressBar, QPushButton, QScrollArea, QTextBrowser,
                               QVBoxLayout, QWidget)

from feelflow.app.exercises.uncertainty import fmt, tied
from feelflow.app.model import readouts

#: parametric kinds: parameter -> (label, minimum, maximum, step); angles in degrees
PARAMETERS = {
    "cylinder": {"diameter": ("Diameter (cells)", 2.0, 60.0, 0.5)},
    "plate": {"length": ("Length (cells)", 2.0, 60.0, 0.5), "thickness": ("Thickness (cells)", 0.5, 20.0, 0.5)},
    "wedge": {"length": ("Length (cells)", 2.0, 60.0, 0.5), "apex_angle": ("Apex angle (degrees)", 5.0, 170.0, 1.0)},
    "half_airfoil": {"chord": ("Chord (cells)", 4.0, 60.0, 0.5), "thickness": ("Thickness (cells)", 0.5, 20.0, 0.25)},
    "naca": {"chord": ("Chord (cells)", 8.0, 120.0, 1.0), "thickness": ("Thickness (x chord)", 0.04, 0.3, 0.01),
             "camber": ("Camber (x chord)", 0.0, 0.09, 0.01), "camber_position": ("Camber at (x chord)", 0.1, 0.9, 0.1)},
}
THUMB = QSize(72, 44)
#: the panel's width in the window (logical pixels): the goal, references and attempts lines wrap to it
PANEL_WIDTH = 340
#: the narrowest it gets (the window keeps 1280 pixels with the forces' toolbar below the flow)
PANEL_MIN_WIDTH = 290
BAD = "#d03030"
GOOD = "#208040"


def thumbnail(outline, best: bool = False) -> QIcon:
    """A small picture of a body outline ((k, 2) points), framed in gold when it is the best."""
    pix = QPixmap(THUMB)
    pix.fill(QColor(41, 43, 48))
    p = QPainter(pix)
    p.setRenderHint(QPainter.Antialiasing)
    xs, ys = [float(x) for x, _ in outline], [float(y) for _, y in outline]
    span = max(max(xs) - min(xs), max(ys) - min(ys), 1e-9)
    k = 0.8 * min(THUMB.width(), THUMB.height() * 1.6) / span
    cx, cy = 0.5 * (max(xs) + min(xs)), 0.5 * (max(ys) + min(ys))
    poly = QPolygonF([QPointF(THUMB.width() / 2 + (x - cx) * k, THUMB.height() / 2 - (y - cy) * k)
                      for x, y in zip(xs, ys)])
    p.setPen(QPen(QColor(20, 20, 20), 1.5))
    p.setBrush(QColor(225, 225, 225))
    p.drawPolygon(poly)
    if best:
        p.setPen(QPen(QColor(255, 200, 0), 3))
        p.setBrush(Qt.NoBrush)
        p.drawRect(1, 1, THUMB.width() - 2, THUMB.height() - 2)
    p.end()
    return QIcon(pix)


def reflow(text: str) -> str:
    """An exercise's text as paragraphs: the file's line breaks inside a paragraph become
    spaces (the panel wraps to its own width), blank lines stay paragraph breaks."""
    paragraphs = [" ".join(line.strip() for line in block.splitlines() if line.strip())
                  for block in text.strip().split("\n\n")]
    return "\n\n".join(p for p in paragraphs if p)


def breakable_path(path: str) -> str:
    """A file path that a word-wrapped label may break after each separator (a zero-width
    space there), with the home folder written as ~."""
    from pathlib import Path

    home = str(Path.home())
    if home not in ("", "/") and path.startswith(home):
        path = "~" + path[len(home):]
    return path.replace("/", "/\u200b").replace("\\", "\\\u200b")


class ScrollingPanel(QScrollArea):
    """The exercise panel in a vertical scroll area: on a short screen it scrolls instead of
    squeezing its wrapped lines over each other."""

    def __init__(self, panel: "ExercisePanel"):
        super().__init__()
        self.setObjectName("exercise_scroll")
        self.setWidget(panel)
        self.setWidgetResizable(True)
        self.setHorizontalScrollBarPolicy(Qt.ScrollBarAlwaysOff)
        self.setMinimumWidth(PANEL_MIN_WIDTH)


class ExercisePanel(QWidget):
    scoreRequested = Signal()
    cancelRequested = Signal()
    attemptChosen = Signal(int)      # index into the attempts list
    parametersChanged = Signal()
    editToggled = Signal(bool)

    def __init__(self, parent=None):
        super().__init__(parent)
        layout = QVBoxLayout(self)
        self.title = QLabel()
        self.title.setWordWrap(True)
        self.title.setStyleSheet("font-weight: bold; font-size: 14px")
        layout.addWidget(self.title)
        self.instructions = QTextBrowser()
        self.instructions.setMinimumHeight(150)
        layout.addWidget(self.instructions, 2)
        self.goal = QLabel()
        self.goal.setWordWrap(True)
        self.goal.setObjectName("exercise_goal")
        layout.addWidget(self.goal)
        self.references = QLabel()
        self.references.setWordWrap(True)
        self.references.setObjectName("exercise_references")
        layout.addWidget(self.references)
        self.edit = QPushButton("Edit vertices")
        self.edit.setCheckable(True)
        self.edit.setToolTip("Drag the yellow handles; double-click an edge to add a vertex; right-click a handle "
                             "to delete it (the same as the Controls panel's Edit vertices)")
        self.edit.toggled.connect(self.editToggled)
        layout.addWidget(self.edit)

        self.shape_box = QGroupBox("Your shape")
        form = QFormLayout(self.shape_box)
        self.kind = QComboBox()
        self.kind.currentIndexChanged.connect(self._kind_changed)
        form.addRow("Kind", self.kind)
        self.spins: dict[str, QDoubleSpinBox] = {}
        self.rows: dict[str, tuple] = {}
        for kind, params in PARAMETERS.items():
            for name, (label, lo, hi, step) in params.items():
                key = f"{kind}.{name}"
                spin = QDoubleSpinBox()
                spin.setRange(lo, hi)
                spin.setSingleStep(step)
                spin.setDecimals(2)
                spin.setKeyboardTracking(False)
                spin.valueChanged.connect(lambda _=0: self.parametersChanged.emit())
                self.spins[key] = spin
                lab = QLabel(label)
                form.addRow(lab, spin)
                self.rows[key] = (lab, spin)
        self.pointing = QComboBox()
        self.pointing.addItem("point upstream <", "upstream")
        self.pointing.addItem("point downstream >", "downstream")
        self.pointing.currentIndexChanged.connect(lambda _=0: self.parametersChanged.emit())
        self.pointing_label = QLabel("Wedge")
        form.addRow(self.pointing_label, self.pointing)
        self.angle = QDoubleSpinBox()
        self.angle.setRange(-90.0, 90.0)
        self.angle.setDecimals(1)
        self.angle.setSingleStep(1.0)
        self.angle.setKeyboardTracking(False)
        self.angle.valueChanged.connect(lambda _=0: self.parametersChanged.emit())
        form.addRow("Angle (degrees, + turns nose down)", self.angle)
        layout.addWidget(self.shape_box)

        self.constraints = QLabel()
        self.constraints.setWordWrap(True)
        self.constraints.setTextFormat(Qt.RichText)
        layout.addWidget(self.constraints)

        row = QHBoxLayout()
        self.score_button = QPushButton("Score it")
        self.score_button.clicked.connect(self.scoreRequested)
        self.cancel_button = QPushButton("Cancel")
        self.cancel_button.clicked.connect(self.cancelRequested)
        self.cancel_button.setEnabled(False)
        row.addWidget(self.score_button)
        row.addWidget(self.cancel_button)
        layout.addLayout(row)
        self.progress = QProgressBar()
        self.progress.setRange(0, 1000)
        self.progress.setTextVisible(True)
        self.progress.setFormat("%p %")
        layout.addWidget(self.progress)
        self.result = QLabel()
        self.result.setWordWrap(True)
        self.result.setTextFormat(Qt.RichText)
        layout.addWidget(self.result)
        #: the live tunnel's coefficients, as the force plot shows them (same reference length)
        self.live = QLabel()
        self.live.setWordWrap(True)
        self.live.setTextFormat(Qt.RichText)
        layout.addWidget(self.live)

        self.attempts_label = QLabel("Attempts")
        self.attempts_label.setWordWrap(True)
        self.attempts_label.setTextInteractionFlags(Qt.TextSelectableByMouse)
        layout.addWidget(self.attempts_label)
        self.attempts = QListWidget()
        self.attempts.setIconSize(THUMB)
        self.attempts.setMinimumHeight(120)
        self.attempts.itemDoubleClicked.connect(lambda item: self.attemptChosen.emit(self.attempts.row(item)))
        layout.addWidget(self.attempts, 2)
        self.load_button = QPushButton("Load this attempt into the editor")
        self.load_button.clicked.connect(self._load_clicked)
        layout.addWidget(self.load_button)

    # --- filling in ---------------------------------------------------------------------------
    def show_exercise(self, exercise):
        self.title.setText(exercise.title)
        self.instructions.setPlainText(reflow(exercise.instructions))
        o = exercise.objective
        goal = f"Goal: {o.kind.replace('_', ' ')}; score = {o.quantity}, {o.better} is better"
        if o.target is not None:
            goal += f" (a hit is within {o.tolerance:g} of {o.target:g})"
        u = o.uncertainty
        if u is not None:
            goal += f". Scores are good to \u00b1{u:g} (the grid uncertainty); closer than that is a tie"
        self.goal.setText(goal + ".")
        refs = "; ".join(f"{r.label}: {fmt(r.score, u)}" for r in exercise.references)
        self.references.setText(f"Reference solution{'s' if len(exercise.references) > 1 else ''}: {refs}.")
        self.edit.setVisible("polygon" in exercise.kinds)
        parametric = [k for k in exercise.kinds if k in PARAMETERS]
        self.shape_box.setVisible(bool(parametric))
        self.kind.blockSignals(True)
        self.kind.clear()
        for k in parametric:
            self.kind.addItem(k.replace("_", " "), k)
        self.kind.blockSignals(False)
        self._show_rows()
        self.result.clear()
        self.progress.setValue(0)

    def _kind_changed(self, _=0):
        self._show_rows()
        self.parametersChanged.emit()

    def _show_rows(self):
        kind = self.kind.currentData()
        for key, (lab, spin) in self.rows.items():
            on = key.split(".")[0] == kind
            lab.setVisible(on)
            spin.setVisible(on)
        self.pointing.setVisible(kind == "wedge")
        self.pointing_label.setVisible(kind == "wedge")

    def set_parameters(self, shape):
        """Show a built-in body's parameters (angles in degrees) without emitting a change per field."""
        d = shape.to_dict()
        widgets = [self.kind, self.pointing, self.angle, *self.spins.values()]
        for w in widgets:
            w.blockSignals(True)
        self.kind.setCurrentIndex(self.kind.findData(d["kind"]))
        for name in PARAMETERS.get(d["kind"], {}):
            value = d[name]
            self.spins[f"{d['kind']}.{name}"].setValue(math.degrees(value) if name == "apex_angle" else value)
        if "pointing" in d:
            self.pointing.setCurrentIndex(self.pointing.findData(d["pointing"]))
        self.angle.setValue(math.degrees(d["angle"]))
        for w in widgets:
            w.blockSignals(False)
        self._show_rows()

    def parameters(self) -> dict:
        """The shape dictionary (shapes/io.py: radians) the parameter fields describe, at (0, 0)."""
        kind = self.kind.currentData()
        d = {"kind": kind, "x": 0.0, "y": 0.0, "angle": math.radians(self.angle.value())}
        for name in PARAMETERS[kind]:
            value = self.spins[f"{kind}.{name}"].value()
            d[name] = math.radians(value) if name == "apex_angle" else value
        if kind == "wedge":
            d["pointing"] = self.pointing.currentData()
        return d

    def show_live(self, readout):
        """The live tunnel's C_D and C_L (an app.model.readouts.Readout) with their reference."""
        fmt = readouts.format_coefficient
        self.live.setText(f"In the tunnel now: C<sub>D</sub> {fmt(readout.cd)}, C<sub>L</sub> {fmt(readout.cl)} "
                          f"<small>({readout.reference_text()}; the window's flow, float32)</small>")

    def show_result(self, text: str):
        """The scoring run's line, or its verdict (app/exercises/score_text.py words it)."""
        self.result.setText(text)

    def show_editing(self, on: bool):
        """Edit vertices checked or not, as the Controls panel's button is (no editToggled)."""
        self.edit.blockSignals(True)
        self.edit.setChecked(on)
        self.edit.blockSignals(False)

    def set_problems(self, problems: list[str]):
        if problems:
            items = "".join(f"<li>{p}</li>" for p in problems)
            self.constraints.setText(f"<span style='color:{BAD}'><b>Not ready to score:</b><ul>{items}</ul></span>")
        else:
            self.constraints.setText(f"<span style='color:{GOOD}'><b>All constraints met</b>: ready to score.</span>")
        self.score_button.setEnabled(not problems and not self.cancel_button.isEnabled())

    def set_running(self, running: bool, problems_ok: bool = True):
        self.cancel_button.setEnabled(running)
        self.score_button.setEnabled(not running and problems_ok)
        self.load_button.setEnabled(not running)
        self.shape_box.setEnabled(not running)
        if running:
            self.progress.setValue(0)

    def set_progress(self, fraction: float):
        self.progress.setValue(int(round(1000 * fraction)))

    def set_attempts(self, attempts, best, where: str, uncertainty: float | None = None):
        self.attempts_label.setText(f"Attempts, the best framed in gold; saved in {breakable_path(where)}")
        self.attempts_label.setToolTip(where)
        self.attempts.clear()
        for a in attempts:
            shape = a.load_shape()
            text = (f"#{a.number}  {fmt(a.score, uncertainty)}" if a.score is not None else f"#{a.number}  {a.status}")
            text += f"   {a.time.replace('T', ' ')[:19]}, {a.seconds:.1f} s"
            if best is not None and a.number == best.number:
                text += "   \u2605 best"
            elif best is not None and a.score is not None and tied(a.score, best.score, uncertainty):
                text += "   = ties the best"
            item = QListWidgetItem(thumbnail(shape.outline(), best is not None and a.number == best.number), text)
            item.setToolTip(a.reason or f"C_D {a.cd:.4f}, C_L {a.cl:.4f}" if a.cd is not None else a.reason)
            self.attempts.addItem(item)
        if attempts:
            self.attempts.setCurrentRow(len(attempts) - 1)

    def _load_clicked(self):
        row = self.attempts.currentRow()
        if row >= 0:
            self.attemptChosen.emit(row)
