"""Score it, off the window's thread: one scoring at a time in a worker thread, with progress,
Cancel and the result passed back as signals.

The score is `feelflow.app.exercises.scoring.score_shape` in float64 on the solver that
`feelflow exercise score` picks by default (`grading.resolve_backend`, `--backend auto`: the
faster of numpy and the compiled cpu backend, which give the same scores), so the window and
the command line give the same digits.
"""
from __future__ import annotations

import multiprocessing

from PySide6.QtCore import QObject, QThread, Signal

from feelflow.app.exercises import grading, scoring
from feelflow.app.exercises.score_text import CANCELLED


class ScoreWorker(QThread):
    """Runs one scoring in a thread: chooses the solver as `feelflow exercise score` does by
    default (`grading.resolve_backend` with AUTO: timed once per grid in a child process, then
    remembered in the same file the command line reads), then scores on it. The window keeps
    drawing (numpy releases the GIL in its array kernels, the cpu backend's kernels run
    without it)."""

    progressed = Signal(float)
    chosen = Signal(str, str)      # the backend, the line saying why (empty when named)
    scored = Signal(object)        # scoring.Result
    failed = Signal(str)           # CANCELLED or the error's one line

    def __init__(self, exercise, shape, parent=None):
        super().__init__(parent)
        self.exercise, self.shape = exercise, shape
        self.backend: str | None = None
        self._cancel = False

    def cancel(self):
        self._cancel = True

    def run(self):
        try:
            # a spawned child: this process may already run numba's OpenMP threads (the live
            # flow on the cpu backend), and a forked child of such a process aborts in them
            self.backend, why = grading.resolve_backend(grading.AUTO, self.exercise,
                                                        mp_context=multiprocessing.get_context("spawn"))
            self.chosen.emit(self.backend, why or "")
            if self._cancel:
                raise scoring.Cancelled()
            result = scoring.score_shape(self.exercise, self.shape, progress=self.progressed.emit,
                                         cancelled=lambda: self._cancel, backend=self.backend)
        except scoring.Cancelled:
            self.failed.emit(CANCELLED)
        except Exception as exc:  # noqa: BLE001 - shown in one line in the panel, not a traceback
            self.failed.emit(str(exc).splitlines()[0] if str(exc) else type(exc).__name__)
        else:
            self.scored.emit(result)


class ScoringRunner(QObject):
    """One scoring at a time for the window: starts the worker, passes its signals on (with the
    shape scored beside the result), cancels it, waits for it when the window closes; keeps the
    last result and the solver it ran on."""

    progressed = Signal(float)
    chosen = Signal(str, str)      # the backend, the line saying why (empty when named)
    scored = Signal(object, object)   # the shape, its scoring.Result
    failed = Signal(str)           # CANCELLED or the error's one line
    finished = Signal()            # the worker is gone (after scored or failed)

    def __init__(self, parent=None):
        super().__init__(parent)
        self.worker: ScoreWorker | None = None
        self.backend: str | None = None        # the solver the last score ran on (numpy or cpu)
        self.last_result = None                # the last scoring.Result

    @property
    def running(self) -> bool:
        return self.worker is not None

    def start(self, exercise, shape) -> bool:
        if self.running:
            return False
        self.worker = ScoreWorker(exercise, shape, self)
        self.worker.progressed.connect(self.progressed)
        self.worker.chosen.connect(self._chosen)
        self.worker.scored.connect(lambda result, s=shape: self._scored(s, result))
        self.worker.failed.connect(self.failed)
        self.worker.finished.connect(self._done)
        self.worker.start()
        return True

    def _chosen(self, backend, why):
        self.backend = backend
        self.chosen.emit(backend, why)

    def _scored(self, shape, result):
        self.last_result = result
        self.scored.emit(shape, result)

    def _done(self):
        self.worker.deleteLater()
        self.worker = None
        self.finished.emit()

    def cancel(self, _=False):
        if self.worker is not None:
            self.worker.cancel()

    def shutdown(self):
        """Stop a running scoring and wait for its thread (the window is closing)."""
        if self.worker is not None:
            self.worker.cancel()
            self.worker.wait()
