"""An exercise in the real window (Xvfb): open it, edit the polygon, break a constraint (the
panel says why, the outline changes, Score it is refused), fix it, score it in the worker
thread, see the attempt listed and saved, load it back; the window's score has the digits
`feelflow exercise score` gives the same shape, on the solver it chooses by default."""
from __future__ import annotations

import json
import pathlib

import pytest

pytestmark = pytest.mark.gui

ROOT = pathlib.Path(__file__).resolve().parents[1]
TINY = ROOT / "tests" / "data" / "exercises" / "tiny.toml"
SQUARE = [(-3.0, -3.0), (3.0, -3.0), (3.0, 3.0), (-3.0, 3.0)]
TALL = [(-3.0, -5.0), (3.0, -5.0), (3.0, 5.0), (-3.0, 5.0)]          # 10 cells high: too tall
ARROW = [(-3.0, 0.0), (0.0, -3.0), (4.0, -3.0), (4.0, 3.0), (0.0, 3.0)]   # 6 high, pointed nose


def remember_scoring_backend(monkeypatch, tmp_path, exercise, backend: str):
    """A user cache (XDG_CACHE_HOME) in tmp_path where `--backend auto` has already chosen
    `backend` for `exercise`'s grid, as a first timing would have (app/exercises/grading.py)."""
    from feelflow.app.exercises import grading
    from feelflow.app.model.backend_choice import JsonFileStore, choice_key, default_store_path

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    s = exercise.scene
    JsonFileStore(default_store_path()).set(choice_key(grading.CHOICE_KEY, s.nx, s.ny), backend)


def test_edit_violate_fix_score_and_list_the_attempt(window, qtbot, tmp_path, monkeypatch):
    """The window scores on the solver `feelflow exercise score` chooses by default (here the
    choice is remembered as numpy: the compiled cpu backend's float64 kernels are not compiled
    in the default tier; test_window_times_the_solvers_and_scores_as_the_command_line does)."""
    from PySide6.QtCore import Qt
    from PySide6.QtWidgets import QMessageBox

    from feelflow.app.exercises import grading
    from feelflow.app.exercises.format import load_exercise
    from feelflow.app.shape_files import save_shape

    remember_scoring_backend(monkeypatch, tmp_path, load_exercise(TINY), "numpy")
    asked = []
    resolve = grading.resolve_backend
    monkeypatch.setattr(grading, "resolve_backend", lambda backend, *a, **k: asked.append(backend) or resolve(backend, *a, **k))
    warnings = []
    monkeypatch.setattr(QMessageBox, "warning", lambda *a, **k: warnings.append(a[2]))
    ex = window.exercises
    ex.attempts.work_folder = tmp_path / "work"
    assert ex.open(TINY)
    panel = ex.panel
    assert panel.isVisible() and "Tiny test exercise" in panel.title.text()
    assert "Least drag" in panel.instructions.toPlainText()
    assert (window.sim.config.nx, window.sim.config.ny) == (64, 32)
    qtbot.waitUntil(lambda: "All constraints met" in panel.constraints.text(), timeout=5000)

    # violate: too tall
    assert window.bodies.edit_polygon(TALL)
    qtbot.waitUntil(lambda: "Not ready" in panel.constraints.text(), timeout=5000)
    assert "frontal height" in panel.constraints.text() and "10.00 cells" in panel.constraints.text()
    assert window.viewport.body_edge is not None
    assert not panel.score_button.isEnabled()
    assert not ex.score() and "frontal height" in warnings[-1]

    # fix it
    assert window.bodies.edit_polygon(ARROW)
    qtbot.waitUntil(lambda: "All constraints met" in panel.constraints.text(), timeout=5000)
    assert window.viewport.body_edge is None and panel.score_button.isEnabled()

    # score in the worker thread: the window keeps running while it does
    frames = window.viewport.frames
    qtbot.mouseClick(panel.score_button, Qt.LeftButton)
    assert panel.cancel_button.isEnabled()
    qtbot.waitUntil(lambda: panel.attempts.count() == 1 and not ex.scoring.running, timeout=300000)
    assert window.viewport.frames > frames
    result = ex.scoring.last_result
    assert result.ok and "Score" in panel.result.text()
    assert "\u2605 best" in panel.attempts.item(0).text() and f"{result.score:.4f}" in panel.attempts.item(0).text()
    saved = json.loads((tmp_path / "work" / "tiny.attempts.json").read_text())
    assert saved["attempts"][0]["score"] == result.score

    # the command line's path (its default, --backend auto) gives the same digits for the same shape
    assert asked == [grading.AUTO] and ex.scoring.backend == "numpy" and "s on numpy)" in panel.result.text()
    shape_file = tmp_path / "arrow.json"
    save_shape(shape_file, ex.attempts.record.items[0].load_shape())
    backend, _ = grading.resolve_backend(grading.AUTO, ex.exercise)
    row = grading.score_file(ex.exercise, shape_file, backend=backend)
    assert backend == ex.scoring.backend
    assert row.score == result.score and row.cd == result.cd and row.cl == result.cl

    # edit again, then load the attempt back into the editor
    assert window.bodies.edit_polygon(SQUARE)
    panel.attempts.setCurrentRow(0)
    qtbot.mouseClick(panel.load_button, Qt.LeftButton)
    assert [tuple(v) for v in window.sim.polygon] == ARROW

    # cancel a second scoring: no attempt is added
    assert ex.score()
    ex.cancel()
    qtbot.waitUntil(lambda: not ex.scoring.running, timeout=60000)
    assert "cancelled" in panel.result.text() and panel.attempts.count() == 1


def test_exercise_on_a_built_in_body_uses_the_parameter_fields(window, qtbot, tmp_path):
    ex = window.exercises
    ex.attempts.work_folder = tmp_path / "work"
    assert ex.open(ROOT / "exercises" / "lift_to_drag.toml")
    panel = ex.panel
    assert panel.shape_box.isVisible()
    qtbot.waitUntil(lambda: "All constraints met" in panel.constraints.text(), timeout=5000)
    panel.shape_box.angle.setValue(30.0)        # outside -12..12
    qtbot.waitUntil(lambda: "the angle is 30.0 degrees" in panel.constraints.text(), timeout=5000)
    panel.shape_box.angle.setValue(-4.0)
    qtbot.waitUntil(lambda: "All constraints met" in panel.constraints.text(), timeout=5000)
    assert ex.current_shape().kind == "half_airfoil"


def test_bad_exercise_file_is_a_dialog(window, tmp_path, monkeypatch):
    from PySide6.QtWidgets import QMessageBox

    shown = []
    monkeypatch.setattr(QMessageBox, "warning", lambda *a, **k: shown.append(a[2]))
    import shutil

    shutil.copytree(TINY.parent / "shapes", tmp_path / "shapes")
    bad = tmp_path / "bad.toml"
    bad.write_text(TINY.read_text().replace("kind = \"least_cd\"", "kind = \"fastest\""))
    assert not window.exercises.open(bad)
    assert len(shown) == 1 and "objective.kind" in shown[0]


def test_plot_overlay_exercise_panel_and_csv_agree_on_one_frame(window, qtbot, tmp_path):
    """One definition of C_D and C_L (app/model/readouts.py): with an exercise open, the force
    plot's readout, the exercise panel's live line, the overlay's arrows and the exported CSV use
    the exercise's reference length and show the same coefficients for the same frame."""
    import csv
    import math

    from feelflow.app.model import readouts

    ex = window.exercises
    ex.attempts.work_folder = tmp_path / "work"
    assert ex.open(TINY)
    length = ex.exercise.scene.reference_length
    sim, plot = window.sim, window.plot
    qtbot.waitUntil(lambda: len(sim.history) > readouts.READOUT_SAMPLES + 5, timeout=30000)
    window.loop.set_paused(True)                              # hold one frame
    plot.refresh(force=True)
    ex.refresh_live()
    r = plot.readout()
    assert r.length.cells == length and r.length.name == readouts.EXERCISE_LENGTH
    assert math.isfinite(r.cd) and r.cd > 0
    assert f"L = {length:g} cells" in plot.readout_box.reference_label.text()
    shown = readouts.format_coefficient(r.cd)
    assert f"= {shown}" in plot.readout_box.value_label.text() and f"C<sub>D</sub> {shown}," in ex.panel.live.text()
    assert r.reference_text() in ex.panel.live.text()

    path = tmp_path / "forces.csv"
    plot.export_csv(path)
    rows = list(csv.DictReader(path.open()))
    model = sim.params.force_model
    tail = [float(row[f"{model}_cd"]) for row in rows[-readouts.READOUT_SAMPLES:]]
    assert sum(tail) / len(tail) == pytest.approx(r.cd, rel=1e-4)   # the body holds still: U is the same each row
    assert rows[-1]["ref_length_cells"] == f"{length:g}"

    # the arrows of the last frame: length = |coefficient| x half the reference length
    window.loop.overlays.update_arrows({model: sim.history.forces[model][-1]})
    arrows = window.viewport.arrow_forces
    ref = sim.reference_length()
    assert readouts.arrow_coefficient(arrows["drag"], ref) == pytest.approx(abs(float(rows[-1][f"{model}_cd"])), rel=1e-4)
    assert readouts.arrow_coefficient(arrows["lift"], ref) == pytest.approx(abs(float(rows[-1][f"{model}_cl"])), rel=1e-4)
    ex.close()
    assert sim.reference_length().name == readouts.BODY_SIZE


@pytest.mark.slow
def test_window_times_the_solvers_and_scores_as_the_command_line(window, qtbot, tmp_path, monkeypatch):
    """With nothing remembered, Score it times numpy against the compiled cpu backend on the
    exercise's grid (a spawned child: the window's process may run numba's threads), scores on
    the faster, and the command line's default then uses the same remembered choice; the score
    equals numpy's within the documented tolerance, 1e-12 relative (docs/guide/exercises.md)."""
    from feelflow.app.exercises import grading
    from feelflow.app.shape_files import save_shape
    from feelflow.app.model.backend_choice import default_store_path

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    ex = window.exercises
    ex.attempts.work_folder = tmp_path / "work"
    assert ex.open(TINY)
    assert window.bodies.edit_polygon(ARROW)
    qtbot.waitUntil(lambda: "All constraints met" in ex.panel.constraints.text(), timeout=5000)
    assert ex.score()
    qtbot.waitUntil(lambda: not ex.scoring.running, timeout=600000)
    result = ex.scoring.last_result
    assert result.ok and ex.scoring.backend in ("numpy", "cpu"), ex.panel.result.text()
    assert default_store_path().exists()
    backend, why = grading.resolve_backend(grading.AUTO, ex.exercise)
    assert backend == ex.scoring.backend and "remembered" in why
    shape_file = tmp_path / "arrow.json"
    save_shape(shape_file, ex.attempts.record.items[0].load_shape())
    cli = grading.score_file(ex.exercise, shape_file, backend=backend)
    reference = grading.score_file(ex.exercise, shape_file, backend="numpy")
    for row in (cli, reference):   # C_L of this symmetric body is round-off (1e-16): to 1e-12 of C_D
        assert row.score == pytest.approx(result.score, rel=1e-12, abs=0)
        assert row.cd == pytest.approx(result.cd, rel=1e-12, abs=0)
        assert row.cl == pytest.approx(result.cl, rel=0, abs=1e-12 * abs(result.cd))
