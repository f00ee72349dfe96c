"""The window's one-line dialogs: bad input or a failed file operation is one plain sentence,
never a traceback (docs/developer/architecture.md, rule 7)."""
from __future__ import annotations

from PySide6.QtWidgets import QMessageBox, QWidget

from feelflow.app.errors import UserError


def attempt(parent: QWidget, fn, title: str):
    """fn()'s result, or None after a one-line dialog when it raised OSError, ValueError
    (ShapeError, SessionError, ConfigError) or UserError, each one line."""
    try:
        return fn()
    except (OSError, ValueError, UserError) as exc:
        QMessageBox.warning(parent, title, str(exc))
        return None
