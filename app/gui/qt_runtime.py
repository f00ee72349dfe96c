"""Guard against a PySide6 6.12 defect on Python 3.11: every C++ method that returns void
decrements the reference count of `None` once (measured here: QPainter.setPen, QPen.setWidth,
QLabel.setText, ... each -1 per call), and pyqtgraph's painting does the same to True/False
somewhere. A window that paints for a minute or two then aborts with "Fatal Python error:
none_dealloc: deallocating None" (or bool_dealloc). Python 3.12 made these singletons immortal
(PEP 683), where the defect is harmless; on older Pythons we do the same by giving them a
reference count no program can use up. Call before any Qt object exists.

pyproject.toml pins PySide6-Essentials below 6.12 (6.11.3 measured healthy here: no drop over
100 000 void calls), so this guard only acts where someone installed an affected PySide6 by
hand; it measures the defect first and does nothing on a healthy PySide6.
"""
from __future__ import annotations

import ctypes
import platform
import sys

_DONE = False


def none_refcount_leak_per_call() -> int:
    """How much one void Qt call lowers None's reference count (0 on a healthy PySide6)."""
    from PySide6.QtGui import QPen

    pen = QPen()
    before = sys.getrefcount(None)
    for _ in range(10):
        pen.setWidth(1)
    return round((before - sys.getrefcount(None)) / 10)


def make_none_immortal() -> None:
    global _DONE
    if _DONE or sys.version_info >= (3, 12) or platform.python_implementation() != "CPython":
        return
    if none_refcount_leak_per_call() <= 0:  # a healthy PySide6: nothing to guard against
        _DONE = True
        return
    # the objects 3.12 makes immortal that a void/bool/int return can hand out
    singletons = [None, True, False, Ellipsis, NotImplemented, (), ""] + list(range(-5, 257))
    for obj in singletons:
        # ob_refcnt is the first field of every CPython object (Include/object.h)
        ctypes.c_ssize_t.from_address(id(obj)).value += 1 << 60
    _DONE = True
