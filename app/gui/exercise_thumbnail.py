"""An attempt's thumbnail in the exercise panel's list: the body's outline, filled, scaled to
fit, framed in gold for the best attempt."""
from __future__ import annotations

from PySide6.QtCore import QPointF, QSize, Qt
from PySide6.QtGui import QColor, QIcon, QPainter, QPen, QPixmap, QPolygonF

THUMB = QSize(72, 44)


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
