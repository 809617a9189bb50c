"""krl.pool.run_tasks with groups (``group``): each worker takes the tasks of one group after
the other, so that what a task loads (a backup's checked workspace, cached per process) is
loaded by one worker, not by every one; every task still runs once, with its own timeout, and
a worker that dies fails only its own task."""

from __future__ import annotations

import os
import time

from krl.pool import Outcome, _Groups, run_tasks


def _where(key, group: str, seconds: float) -> tuple:
    """The worker's pid, the task's key and group (after `seconds` of work)."""
    time.sleep(seconds)
    return os.getpid(), key, group


def _die(key, group, _seconds):
    if key == "b2":
        os._exit(3)
    return _where(key, group, 0.0)


def test_each_group_runs_in_one_worker_while_groups_are_left_to_start():
    # groups a and b of two tasks, c of four, two workers: a and b are given out whole at the
    # start (two in flight per worker), one to each worker, so they run there whatever the
    # machine's load; c is started by the first to finish and may be helped by the other
    tasks = [(f"{g}{i}", (f"{g}{i}", g, 0.05)) for g, n in (("a", 2), ("b", 2), ("c", 4)) for i in range(n)]
    got = list(run_tasks(_where, tasks, jobs=2, group=lambda key: key[0]))
    assert sorted(o.key for o in got) == sorted(k for k, _ in tasks)
    assert all(o.status == "done" for o in got)
    pids = {}
    for o in got:
        pids.setdefault(o.value[2], set()).add(o.value[0])
    assert len(pids["a"]) == 1 and len(pids["b"]) == 1 and pids["a"] != pids["b"]
    assert len({p for s in pids.values() for p in s}) == 2


def test_the_order_in_which_slots_take_groups():
    """krl.pool._Groups on its own: the order is the rule's, with no worker in between."""
    tasks = [(f"{g}{i}", ()) for g, n in (("a", 3), ("b", 1), ("c", 4)) for i in range(n)]
    feed = _Groups(tasks, lambda key: key[0], 2)
    taken = {0: [], 1: []}

    def take(slot, inflight):
        task = feed.next(slot, inflight)
        if task is not None:
            taken[slot].append(task[0])
        return task

    assert take(0, 0) and take(0, 1) and take(0, 2) is None    # two in flight at most
    assert take(1, 0) and take(1, 1)                            # b's one task, then c: no group left to start
    assert taken == {0: ["a0", "a1"], 1: ["b0", "c0"]}
    take(0, 1)                                                  # its own group first
    take(0, 1)                                                  # a has none left: the group with most left, c
    take(1, 1)
    take(1, 1)
    assert taken == {0: ["a0", "a1", "a2", "c1"], 1: ["b0", "c0", "c2", "c3"]}
    assert feed.next(0, 0) is None and feed.next(1, 0) is None


def test_grouped_tasks_keep_their_timeout_and_a_death_fails_only_its_task():
    tasks = [("a1", ("a1", "a", 0.0)), ("a2", ("a2", "a", 5.0)), ("b1", ("b1", "b", 0.0)), ("b2", ("b2", "b", 0.0)),
             ("b3", ("b3", "b", 0.0))]
    got = {o.key: o for o in run_tasks(_die, tasks, jobs=2, timeout=60, group=lambda key: key[0])}
    assert got["b2"].status == "internal_error" and "exit status 3" in got["b2"].detail
    assert all(got[k].status == "done" for k in ("a1", "a2", "b1", "b3"))
    slow = {o.key: o for o in run_tasks(_where, [("a1", ("a1", "a", 3.0)), ("b1", ("b1", "b", 0.0))],
                                        jobs=2, timeout=0.5, group=lambda key: key[0])}
    assert slow["a1"].status == "timeout" and slow["b1"].status == "done"


def test_one_job_or_no_group_runs_as_before():
    tasks = [(i, (i, "g", 0.0)) for i in range(5)]
    for kw in ({"jobs": 1, "group": lambda k: k % 2}, {"jobs": 2}):
        got = list(run_tasks(_where, tasks, **kw))
        assert sorted(o.key for o in got) == list(range(5)) and all(isinstance(o, Outcome) for o in got)
        assert all(o.status == "done" and o.value[1] == o.key for o in got)     # each task's own result
        if kw["jobs"] == 1:
            assert len({o.value[0] for o in got}) == 1                          # one worker
