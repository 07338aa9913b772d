"""Timing controller calls: clock overhead, per-call wall times, their statistics."""

from __future__ import annotations

import gc
import statistics
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

Clock = Callable[[], int]

#: Fewest samples a 99th percentile is judged from: with fewer than 1 / (1 - 0.99) = 100,
#: the interpolated p99 is (nearly) the largest sample, i.e. one preempted call.
P99_MIN_SAMPLES = 100


def p99_judgeable(samples: int) -> bool:
    """Whether a 99th percentile over ``samples`` values may be judged against a target
    (at least :data:`P99_MIN_SAMPLES`)."""
    return samples >= P99_MIN_SAMPLES


def timer_overhead_ns(clock: Clock = time.perf_counter_ns, samples: int = 2001) -> float:
    """Median cost (ns) of one pair of clock reads: subtracted from every timed call."""
    gaps = []
    for _ in range(samples):
        start = clock()
        gaps.append(clock() - start)
    return float(statistics.median(gaps))


def time_calls(
    command: Callable[..., Any],
    calls: Sequence[tuple[Any, ...]],
    repeats: int,
    clock: Clock = time.perf_counter_ns,
    overhead_ns: float = 0.0,
    between: Callable[[], None] | None = None,
) -> np.ndarray:
    """Wall time (us) of every call, shape ``(repeats, len(calls))``: each repeat replays the
    calls in their recorded order (garbage collector paused), ``between`` runs after each
    repeat (e.g. a controller reset). The clock-read overhead is subtracted."""
    times = np.zeros((repeats, len(calls)))
    gc_was_enabled = gc.isenabled()
    gc.disable()
    try:
        for r in range(repeats):
            row = times[r]
            for i, args in enumerate(calls):
                start = clock()
                command(*args)
                row[i] = clock() - start
            if between is not None:
                between()
    finally:
        if gc_was_enabled:
            gc.enable()
    return np.maximum(times - overhead_ns, 0.0) / 1000.0


def summarize_times(times: np.ndarray) -> dict[str, Any]:
    """Median, 90th and 99th percentile over states of each state's median over the
    repeats (``times``: repeats x states, us), and the median of each repeat's median."""
    per_state = np.median(times, axis=0)
    return {
        "median_us": float(np.median(per_state)),
        "p90_us": float(np.percentile(per_state, 90)),
        "p99_us": float(np.percentile(per_state, 99)),
        "max_us": float(np.max(per_state)),
        "repeat_medians_us": [float(v) for v in np.median(times, axis=1)],
    }
