"""Tasks of a sweep on threads of this process (the native loops release the GIL), and the regrouping of
independent points into tasks that shrink as the sweep goes."""
from __future__ import annotations

import queue
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from .grid import INDEPENDENT, Point
from .point_runs import PointRuns

def guided(tasks: list[tuple[list[Point], np.ndarray]], workers: int) -> list[tuple[list[Point], np.ndarray]]:
    """Independent points (a task each, all from the same start) regrouped into tasks that shrink as the
    sweep goes: each takes half of what is left per worker, down to single points. A task's points are
    summarised as one batch, so few large tasks cost little around each point, and the small ones at the
    end keep the workers finishing together. Continuation lines are left as they are."""
    if not tasks or tasks[0][0][0].direction != INDEPENDENT:
        return tasks
    points, start, out = [p for task, _ in tasks for p in task], tasks[0][1], []
    while points:
        size = max(1, -(-len(points) // (2 * workers))) if workers > 1 else len(points)
        out.append((points[:size], start))
        points = points[size:]
    return out


def execute_threads(run: PointRuns, tasks: list[tuple[list[Point], np.ndarray]], jobs: int):
    """Yield batches of (row, Poincare rows) as points finish; tasks run on up to ``jobs`` threads."""
    if not tasks:
        return
    if jobs == 1 or len(tasks) == 1:  # no threads: simplest, and Ctrl-C stops at once
        for task, state in tasks:
            yield from run.task(run.compiled, task, state)
        return
    results: queue.Queue = queue.Queue()
    stop = threading.Event()
    local = threading.local()

    def work(task, state):
        compiled = getattr(local, "compiled", None)
        if compiled is None:
            compiled = local.compiled = run.compiled.clone()
        if stop.is_set():
            return
        for batch in run.task(compiled, task, state):
            results.put(batch)
            if stop.is_set():  # checked before the next batch is computed
                return

    pool = ThreadPoolExecutor(max_workers=min(jobs, len(tasks)), thread_name_prefix="gearsym-sweep")
    futures = [pool.submit(work, task, state) for task, state in tasks]
    try:
        pending = sum(len(t) for t, _ in tasks)
        while pending:
            try:
                item = results.get(timeout=0.2)
            except queue.Empty:
                failed = next((f for f in futures if f.done() and f.exception()), None)
                if failed:
                    raise failed.exception()
                continue
            pending -= len(item)
            yield item
    finally:
        stop.set()  # on an error or Ctrl-C: threads stop after their current batch
        pool.shutdown(wait=True, cancel_futures=True)  # points finished meanwhile are redone on resume
