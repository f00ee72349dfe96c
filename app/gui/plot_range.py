"""The force plot's ranges: the plot sets them (app/model/plot_series.py computes them) until
the user zooms or pans, and again once the user clicks pyqtgraph's auto-range button ("A") or
another view is chosen."""
from __future__ import annotations


class RangeFollower:
    """Sets the ranges of `plot` (a pyqtgraph PlotWidget) while `follow` is True."""

    def __init__(self, plot):
        self.plot = plot
        self.follow = True
        plot.getViewBox().sigRangeChangedManually.connect(self._user_moved)

    def _user_moved(self, *_):
        self.follow = False

    def following(self) -> bool:
        """Is the plot to set its own ranges? Yes until the user zooms or pans, and again once
        the user clicks the auto-range button ("A" turns both axes' auto-range on; a zoom of
        one axis turns that one off)."""
        if all(self.plot.getViewBox().autoRangeEnabled()):
            self.follow = True
        return self.follow

    def restart(self):
        """A new view: the plot follows again, pyqtgraph's auto-range until it sets a range."""
        self.follow = True
        self.plot.enableAutoRange()

    def set_y(self, span):
        """The force axis to `span` (low, high) with a margin; pyqtgraph's own auto-range while
        `span` is None (nothing settled yet)."""
        if not self.following():
            return
        if span is None:
            self.plot.enableAutoRange(y=True)
        else:
            self.plot.setYRange(*span, padding=0.08)

    def set_log(self, x, y):
        """Both axes of a log-log view to log10 ranges `x`, `y`."""
        if not self.following():
            return
        self.plot.setXRange(*x, padding=0)
        self.plot.setYRange(*y, padding=0)
