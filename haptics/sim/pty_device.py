"""A device simulator behind a real pseudo-terminal: bytes the host writes to the tty arrive
here, answers go back through the same pty (so pyserial, the line discipline and timing are real)."""
from __future__ import annotations

import os
import select
import threading
import tty

from feelflow.haptics.timing import try_realtime


class PtyDevice:
    """Base: runs `on_bytes(data) -> reply bytes` in a thread on the pty's master side."""

    def __init__(self):
        self._master, self._slave = os.openpty()
        tty.setraw(self._slave)
        self.port = os.ttyname(self._slave)
        self._stop = threading.Event()
        self._lock = threading.Lock()
        self.bytes_in = 0
        self.errors: list[str] = []  # exceptions raised while answering (should stay empty)
        self.muted = False  # True: the device hangs (reads, never answers) without closing the port
        self._thread = threading.Thread(target=self._run, name=f"sim:{self.port}", daemon=True)
        self._thread.start()

    def on_bytes(self, data: bytes) -> bytes:  # pragma: no cover - overridden
        return b""

    def _run(self) -> None:
        # A real board has its own processor; give the simulated one a real-time slot when
        # allowed, so it is not descheduled while holding the GIL the force loop needs.
        try_realtime(9)
        while not self._stop.is_set():
            fd = self._master
            if fd is None:
                break
            try:
                ready, _, _ = select.select([fd], [], [], 0.05)
                if not ready:
                    continue
                data = os.read(fd, 4096)
            except (OSError, ValueError, TypeError):
                break
            if not data:
                break
            self.bytes_in += len(data)
            if self.muted:
                continue
            try:
                reply = self.on_bytes(data)
            except Exception as exc:  # a simulator bug must show, not silently hang the port
                self.errors.append(repr(exc))
                continue
            if reply:
                self.inject(reply)

    def inject(self, data: bytes) -> None:
        """Send raw bytes to the host (tests use this for malformed or truncated packets)."""
        with self._lock:
            if self._master is None:
                return
            try:
                os.write(self._master, data)
            except OSError:
                pass

    def disconnect(self) -> None:
        """Pull the cable: close the pty; the host's next read or write fails."""
        self._stop.set()
        with self._lock:
            for fd in (self._master, self._slave):
                try:
                    os.close(fd)
                except (OSError, TypeError):
                    pass
            self._master = self._slave = None

    def stop(self) -> None:
        self.disconnect()
        if self._thread is not threading.current_thread():
            self._thread.join(timeout=1.0)
