"""Vehicles open at once, and whatever opened is taken down again whoever failed."""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable

import pytest

from gcs.parallel_open import open_in_parallel


def test_every_vehicle_opens_on_its_own_thread_at_the_same_time() -> None:
    # Opened one after another, the first opener would wait at the barrier alone and time out.
    barrier = threading.Barrier(5, timeout=10.0)
    seen_threads: set[str] = set()

    def opener(k: int) -> Callable[[contextlib.ExitStack], int]:
        def open_(stack: contextlib.ExitStack) -> int:
            barrier.wait()
            seen_threads.add(threading.current_thread().name)
            return 10 * k

        return open_

    with contextlib.ExitStack() as stack:
        got = open_in_parallel({k: opener(k) for k in (5, 1, 3, 2, 4)}, stack)
    assert list(got) == [5, 1, 3, 2, 4] and got == {5: 50, 1: 10, 3: 30, 2: 20, 4: 40}
    assert len(seen_threads) == 5


def test_teardown_runs_in_reverse_order_of_the_keys() -> None:
    closed: list[str] = []

    def opener(k: int) -> Callable[[contextlib.ExitStack], int]:
        def open_(stack: contextlib.ExitStack) -> int:
            stack.callback(closed.append, f"{k}:link")
            stack.callback(closed.append, f"{k}:station")  # registered last, stops first
            return k

        return open_

    with contextlib.ExitStack() as stack:
        open_in_parallel({k: opener(k) for k in (1, 2, 3)}, stack)
        assert closed == []
    assert closed == ["3:station", "3:link", "2:station", "2:link", "1:station", "1:link"]


def test_one_failure_is_raised_and_every_other_vehicle_is_closed() -> None:
    closed: list[int] = []
    started = threading.Barrier(3, timeout=10.0)

    def opener(k: int) -> Callable[[contextlib.ExitStack], int]:
        def open_(stack: contextlib.ExitStack) -> int:
            stack.callback(closed.append, k)
            started.wait()  # the failure comes while the others are mid-way
            if k == 2:
                raise OSError("vehicle 2: connection refused")
            return k

        return open_

    with pytest.raises(OSError, match="vehicle 2"), contextlib.ExitStack() as stack:
        open_in_parallel({k: opener(k) for k in (1, 2, 3)}, stack)
    assert sorted(closed) == [1, 2, 3]
    assert closed[0] == 2  # the failed one undid its own part at once


def test_a_single_vehicle_opens_on_the_calling_thread() -> None:
    with contextlib.ExitStack() as stack:
        got = open_in_parallel({1: lambda s: threading.current_thread()}, stack)
    assert got[1] is threading.current_thread()
