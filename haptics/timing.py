"""Keeping a period: sleep until just before the deadline, then spin to it.

`time.sleep` on Linux wakes 50-100 us late on an idle machine and much later on a loaded one;
spinning the last `spin_s` absorbs the usual lateness without burning a core (at 1 kHz a
0.3 ms spin costs ~30 % of one core: the price of sub-ms jitter on a shared 2-core machine;
set spin_s=0 to trade jitter for CPU). Deadlines are absolute (next += period), so lateness
does not accumulate; after a long stall the schedule restarts instead of bursting.
"""
from __future__ import annotations

import os
import time


def try_realtime(priority: int) -> bool:
    """Put the calling thread in SCHED_FIFO at `priority` (Linux, with the right to do so), so
    it wakes on time on a busy machine; False where that is not allowed."""
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))  # 0 = this thread
        return True
    except (OSError, AttributeError):
        return False


class Ticker:
    def __init__(self, rate_hz: float = 1000.0, spin_s: float = 0.0003):
        if not rate_hz > 0:
            raise ValueError("rate must be positive")
        self.period = 1.0 / rate_hz
        self.spin_s = spin_s
        self.next = None
        self.overruns = 0  # schedules restarted after falling more than 5 periods behind

    def wait(self) -> float:
        """Block until the next deadline; returns the time (monotonic) it woke at."""
        now = time.monotonic()
        if self.next is None:
            self.next = now
            return now
        self.next += self.period
        if now - self.next > 5 * self.period:
            self.overruns += 1
            self.next = now
            return now
        while True:
            remaining = self.next - time.monotonic()
            if remaining <= 0:
                return time.monotonic()
            if remaining > self.spin_s:
                time.sleep(remaining - self.spin_s)
