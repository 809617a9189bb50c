"""Helpers of the partner tests: run a program on the simulated controller in this thread
while a partner (written from the protocol, not from our code) talks to it from another
thread over loopback, and stop the run when the partner is done."""

from __future__ import annotations

import socket
import threading
import time
from pathlib import Path

from interp.run import make_runtime, run_spec, RunSinks
from robot.trace import TraceWriter

HERE = Path(__file__).resolve().parent
CONFIGS = HERE / "configs"
PROGRAMS = HERE / "programs"
EXAMPLES = HERE.parents[1] / "examples" / "network"     # the runnable examples of docs/network.md


class PartnerFailed(AssertionError):
    pass


def free_port() -> int:
    """A TCP port of the loopback free now (the channel's place, given before the run)."""
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def connect(port: int, deadline: float) -> socket.socket:
    """A TCP connection to the robot's server on `port` of the loopback, tried until it
    listens (the program opens its channel when it gets there) or `deadline` (monotonic)."""
    while True:
        try:
            return socket.create_connection(("127.0.0.1", port), timeout=5)
        except OSError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.05)


def run_with_partner(program, settings, partner, *, interp: str = "tree", max_sim_time: float = 60.0,
                     wall_timeout: float = 120.0, box: dict | None = None, **kw):
    """Run `program` with network `settings`; `partner(net, rt)` runs in a thread and its
    return value is returned with the run's result and trace: (result, trace, partner_value).
    When the partner returns (or fails) the run is stopped at the next IPO cycle; `box`, when
    given, receives the runtime as ``box["rt"]`` (to read the program's variables after)."""
    trace = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(Path(program), network=settings, max_sim_time=max_sim_time,
                         mujoco=False, interp=interp, **kw), RunSinks(trace=trace))
    net = rt.controller.network
    box = {} if box is None else box

    def body():
        try:
            box["value"] = partner(net, rt)
        except BaseException as exc:       # reported in the test's thread
            box["error"] = exc
        finally:
            rt.scheduler.stop_by(rt.controller.time)   # stop at the next cycle
            _partner_gone(net)

    th = threading.Thread(target=body, daemon=True)
    th.start()
    result = rt.run()
    th.join(wall_timeout)
    if th.is_alive():
        raise PartnerFailed("the partner did not finish")
    if "error" in box:
        raise box["error"]
    box["rt"] = rt
    return result, trace, box.get("value")


def _partner_gone(net) -> None:
    """The partner has returned: nothing answers from now on. The run's RSI sensor is gone
    (net/rsi.py ``Rsi.sensor_gone``), so the controller does not wait ANSWER_WAIT_S of wall time
    for an answer to the last cycle's packets before it stops (2 s per test)."""
    try:
        rsi = net.partner("rsi").rsi
    except (KeyError, AttributeError):
        return
    if rsi is not None:
        rsi.sensor_gone()


def net_events(trace, **match):
    return [e for e in trace.events if e["kind"] == "net" and all(e.get(k) == v for k, v in match.items())]
