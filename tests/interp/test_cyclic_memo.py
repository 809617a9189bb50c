"""A cyclic flag whose expression reads the signals and constants only is evaluated again when a
signal or the flags changed (interp/runtime/cyclic.py ``Cyclic._settles``: IO), not after every
statement: the same run as evaluating it at every IPO cycle (the general path), on drawn input
changes, both interpreters, with a program that runs statements and presets a timer every cycle
(which moves the I/O image's version, not its signals)."""

from __future__ import annotations

import random

import pytest

from interp.runtime.cyclic import Cyclic

from .helpers import run_krl

PROG = """
DEF prog()
  DECL INT n
  SIGNAL Lamp $IN[5]
  $CYCFLAG[2] = $IN[4] AND NOT Lamp OR $IN[6] AND $ALARM_STOP
  $CYCFLAG[3] = $IN[7]
  INTERRUPT DECL 10 WHEN $CYCFLAG[2] DO Rise()
  INTERRUPT ON 10
  n = 0
  WHILE n < 90
    n = n + 1
    $OUT[1] = $CYCFLAG[2]
    $OUT[2] = $CYCFLAG[3] AND $CYCFLAG[2]
    $TIMER[2] = n
    WAIT SEC 0.012
  ENDWHILE
END
DEF Rise()
  $OUT[3] = NOT $OUT[3]
END
"""


def _stimuli(rng: random.Random) -> str:
    lines = ["stimuli:"]
    t = 0.0
    state = dict.fromkeys((4, 5, 6, 7), False)
    for _ in range(16):
        t += rng.choice([0.012, 0.024, 0.03, 0.05, 0.1])
        sig = rng.choice([4, 4, 5, 6, 7])
        state[sig] = not state[sig]
        lines.append(f'  - at: {t:.3f}\n    set: {{"$IN[{sig}]": {"true" if state[sig] else "false"}}}')
    return "\n".join(lines) + "\n"


def _run(tmp_path, stimuli: str, interp: str, general: bool, monkeypatch) -> tuple:
    counts = [0]
    orig_on = Cyclic.on

    def on(self, key, fn):
        def counted():
            counts[0] += 1
            return fn()
        return orig_on(self, key, counted)

    with monkeypatch.context() as m:
        m.setattr(Cyclic, "on", on)
        if general:
            m.setattr(Cyclic, "_settles", lambda self: None)     # evaluated at every IPO cycle
        r = run_krl(tmp_path, PROG, stimuli=stimuli, interp=interp, max_sim_time=1.2, trace=False)
    log = [(round(t, 6), name, v) for t, name, v, _src in r.rt.controller.io.log]
    return (r.result.reason, r.result.steps, log), counts[0]


@pytest.mark.parametrize("interp", ["vm", "tree"])
def test_an_io_cyclic_flag_evaluated_on_io_changes_is_the_flag_evaluated_every_cycle(tmp_path, interp, monkeypatch):
    rng = random.Random(62)
    for k in range(2):
        stimuli = _stimuli(rng)
        fast, n_fast = _run(tmp_path / f"f{k}", stimuli, interp, False, monkeypatch)
        slow, n_slow = _run(tmp_path / f"s{k}", stimuli, interp, True, monkeypatch)
        assert fast == slow
        assert any(name == "$OUT[3]" for _t, name, _v in fast[2])       # the interrupt fired
        assert n_fast * 3 < n_slow, (n_fast, n_slow)                     # evaluations left out
