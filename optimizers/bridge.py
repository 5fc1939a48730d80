"""Ask/tell over a callback-style optimizer: SciPy drives its objective, we drive SciPy.

`Bridge(target)` runs `target(request)` in a daemon thread. Inside it, the
objective calls `request(points)`, which hands the points to the main thread
and blocks until `reply(values)`. On the main thread, `next()` waits for the
worker's next message: ("request", points), or ("done", what `target`
returned) once it has ended. Only one side runs at a time, so a run is as
deterministic as the optimizer. `stop()` ends a worker that is still asking
(its `request` raises `Stop("closed")`, which `target` may catch or let
unwind; an uncaught `Stop` ends the run with its message as the result).
"""

from __future__ import annotations

import queue
import threading
from typing import Any


class Stop(Exception):
    """Raised inside the worker's objective to end the run (the budget is spent, or `stop()`)."""


class Bridge:
    """One worker thread running `target(request)`, and the main thread's side of its requests."""

    def __init__(self, target, name: str):
        self._target = target
        self._to_main: queue.Queue = queue.Queue()
        self._to_worker: queue.Queue = queue.Queue()
        self.thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._awaiting = False  # a request was handed out and not replied to
        self.finished = False

    # worker side

    def request(self, points: object) -> Any:
        """Hand `points` to the main thread; their values, or `Stop` if the run is ended."""
        self._to_main.put(("request", points))
        values = self._to_worker.get()
        if values is None:
            raise Stop("closed")
        return values

    def _run(self) -> None:
        try:
            result = self._target(self.request)
        except Stop as stop:
            self._to_main.put(("done", str(stop)))
        except BaseException as error:  # noqa: BLE001  (handed to the main thread)
            self._to_main.put(("error", error))
        else:
            self._to_main.put(("done", result))

    # main side

    def start(self) -> None:
        self.thread.start()

    @property
    def started(self) -> bool:
        return self.thread.ident is not None

    def next(self) -> tuple[str, object]:
        """The worker's next message: ("request", points) or ("done", result); its error is raised."""
        kind, payload = self._to_main.get()
        if kind == "request":
            self._awaiting = True
            return kind, payload
        self.thread.join()
        self.finished = True
        if kind == "error":
            raise RuntimeError(f"{self.thread.name}: the worker failed") from payload
        return kind, payload

    def reply(self, values: object) -> None:
        """The values of the points last requested."""
        self._awaiting = False
        self._to_worker.put(values)

    def stop(self) -> object:
        """End the worker (if it runs) and wait for it; returns its result (None if it never ran)."""
        if not self.started or self.finished:
            return None
        if self._awaiting:
            self.reply(None)
        while True:
            kind, payload = self.next()
            if kind == "done":
                return payload
            self.reply(None)

    def abandon(self) -> None:
        """Unblock a waiting worker without waiting for it (garbage collection, interpreter exit)."""
        if self.started and not self.finished and self._awaiting:
            self._to_worker.put(None)
