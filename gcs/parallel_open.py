"""Open several vehicles at once: one thread per vehicle for the blocking bring-up.

A vehicle's bring-up (link open, streams, parameter reads, pre-flight checks) waits on the
vehicle for seconds; five of them one after another took 25 s before the first could fly. Each
vehicle is opened on its own thread against its own `ExitStack`, so what it opened is undone in
reverse whatever happens, and the objects it built are touched by that thread alone until it has
finished and handed them back: a vehicle link is a single-owner object.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable, Mapping
from typing import TypeVar

T = TypeVar("T")

Opener = Callable[[contextlib.ExitStack], T]
"""Builds one vehicle, registering on the stack how to take it down again."""


def open_in_parallel(openers: Mapping[int, Opener[T]], stack: contextlib.ExitStack,
                     name: str = "open-vehicle") -> dict[int, T]:
    """Run every opener on its own thread; their results by key, in the mapping's order.

    Each opener's stack is handed to `stack` (entered in key order, so the last key's is undone
    first) once every thread has finished. A failed opener's own stack is closed on its thread;
    the first failure in key order is raised after the others have finished and been handed
    over, so the caller's stack takes them down.
    """
    results: dict[int, T] = {}
    errors: dict[int, BaseException] = {}
    stacks: dict[int, contextlib.ExitStack] = {}

    def run(key: int, opener: Opener[T]) -> None:
        own = contextlib.ExitStack()
        try:
            results[key] = opener(own)
            stacks[key] = own
        except BaseException as exc:  # handed to the caller's thread, re-raised there
            errors[key] = exc
            own.close()

    if len(openers) == 1:  # no thread for the common single-vehicle case
        key, opener = next(iter(openers.items()))
        run(key, opener)
    else:
        threads = [threading.Thread(target=run, args=(k, o), name=f"{name}-{k}", daemon=True)
                   for k, o in openers.items()]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    for key in openers:
        if key in stacks:
            stack.enter_context(stacks[key])
    for key in openers:
        if key in errors:
            raise errors[key]
    return {k: results[k] for k in openers}
