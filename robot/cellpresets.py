"""Presets of the cell: the standard KUKA handshakes as reactive rules (issue 22).

* :func:`pgno_rules` — the PLC side of the program-number handshake of KUKA's P00
  (``R1/TP/p00.src``, routine ``EXT_PGNO``, case ``#PGNO_GET``) as the backups of the corpus
  carry it, with the parameters of the backup's ``$config.dat`` (``PGNO_TYPE``,
  ``PGNO_LENGTH``, ``PGNO_FBIT``, ``PGNO_REQ``, ``PGNO_VALID``, ``PGNO_PARITY``). The protocol
  P00 expects (khrzysio__KRC4_test/R1/TP/p00.src:173-300; "Operating and Programming
  Instructions for System Integrators", KSS 8.x, Automatic External, program number
  transfer):

  1. P00 waits until ``$IN[PGNO_VALID]`` is FALSE, then sets ``$OUT[PGNO_REQ]`` (the robot
     requests a program number);
  2. the PLC puts the number on ``$IN[PGNO_FBIT]`` .. ``$IN[PGNO_FBIT+PGNO_LENGTH-1]``
     (``PGNO_TYPE`` 1: binary, bit 0 on ``PGNO_FBIT``; 2: BCD, four bits a decimal digit,
     units first; 3: one of n, input ``PGNO_FBIT+PGNO-1``), the parity on
     ``$IN[PGNO_PARITY]`` (``> 0``: the EXOR of the bits; ``< 0`` on ``-PGNO_PARITY``: its
     negation; 0: none) and then sets ``$IN[PGNO_VALID]``;
  3. P00 reads the bits (``REPEAT ... UNTIL $IN[PGNO_VALID]==TRUE``); the program acknowledges
     (``#PGNO_ACKN``) by resetting ``$OUT[PGNO_REQ]``; the PLC then resets ``PGNO_VALID``.

  A negative ``PGNO_REQ``/``PGNO_VALID`` is active low on the input or output ``-n``, as P00
  handles it. The PLC answers :data:`PLC_DELAY_S` after the edge it reacts to (one PLC scan
  plus the bus: 0.1 s, a typical figure, not a value of the manual); the number and
  ``PGNO_VALID`` are set in the same cycle, which is what the robot side can observe of a PLC
  that sets the bits first (P00 reads them only after ``PGNO_VALID``). ``PGNO_VALID = 0``
  (the number valid with ``$EXT_START``) is not simulated: :class:`PresetError`.

* ``autoext`` (interp/run.py): the Automatic External interface. The run's operating mode is
  EXT (``$MODE_OP = #EX``), so ``$I_O_ACTCONF`` — TRUE when EXT is selected and ``$I_O_ACT``
  is TRUE (manual, Automatic External outputs) — is TRUE, as P00's ``INIT_EXT`` requires
  (p00.src:56-64). ``$MOVE_ENABLE``, ``$PERI_RDY``, ``$USER_SAF`` keep their boot values
  (TRUE, interp/runtime/sysvars.py): the drives are on, as after the PLC's ``$DRIVES_ON`` pulse.
"""

from __future__ import annotations

from krl.ast import nodes as N

from .cellrules import Rule

#: delay of the PLC's answers in s (one scan plus the field bus; a typical figure).
PLC_DELAY_S = 0.1

#: the $config.dat variables of the handshake
PGNO_PARAMETERS = ("PGNO_TYPE", "PGNO_LENGTH", "PGNO_FBIT", "PGNO_REQ", "PGNO_VALID", "PGNO_PARITY")


class PresetError(ValueError):
    """A preset that the backup's parameters do not allow (message names the parameter)."""


def _signal(base: str, n: int) -> N.Expr:
    return N.Index(N.Name(base), [N.IntLit(n)])


def _active(base: str, n: int) -> tuple[N.Expr, str]:
    """The condition "signal n is active" (active low for a negative n) and its text."""
    if n > 0:
        return _signal(base, n), f"{base}[{n}]"
    return N.Unary("NOT", _signal(base, -n)), f"NOT {base}[{-n}]"


def pgno_bits(number: int, ptype: int, length: int) -> list[bool]:
    """The program-number inputs, first bit first, for `number` coded as ``PGNO_TYPE``
    `ptype` on `length` bits. Raises :class:`PresetError` when the number does not fit."""
    if ptype == 1:
        if not 0 <= number < (1 << length):
            raise PresetError(f"program number {number} does not fit on PGNO_LENGTH={length} bits")
        return [bool((number >> i) & 1) for i in range(length)]
    if ptype == 2:
        if length % 4 or not 0 <= number < 10 ** (length // 4):
            raise PresetError(f"program number {number} does not fit BCD on PGNO_LENGTH={length} bits")
        bits = []
        for digit in range(length // 4):
            d = (number // 10 ** digit) % 10
            bits += [bool((d >> i) & 1) for i in range(4)]
        return bits
    if ptype == 3:
        if not 1 <= number <= length:
            raise PresetError(f"program number {number} is not one of 1..PGNO_LENGTH={length}")
        return [i == number - 1 for i in range(length)]
    raise PresetError(f"PGNO_TYPE={ptype} is not 1 (binary), 2 (BCD) or 3 (one of n)")


def pgno_rules(params: dict[str, int], number: int) -> list[Rule]:
    """The PLC's rules of the program-number handshake answering `number` (see the module
    docstring). `params`: the ``PGNO_*`` values of the backup's ``$config.dat``.

    Raises :class:`PresetError` for a missing parameter, ``PGNO_VALID = 0`` or a number that
    does not fit."""
    missing = [k for k in PGNO_PARAMETERS if k not in params]
    if missing:
        raise PresetError(f"the backup's $config.dat does not declare {', '.join(missing)}")
    ptype, length, fbit = params["PGNO_TYPE"], params["PGNO_LENGTH"], params["PGNO_FBIT"]
    req, valid, parity = params["PGNO_REQ"], params["PGNO_VALID"], params["PGNO_PARITY"]
    if req == 0:
        raise PresetError("PGNO_REQ=0: the backup requests no program number")
    if valid == 0:
        raise PresetError("PGNO_VALID=0 (number valid with $EXT_START) is not simulated")
    bits = pgno_bits(number, ptype, length)
    answer: dict[str, object] = {f"$IN[{fbit + i}]": b for i, b in enumerate(bits)}
    odd = False
    for b in bits:
        odd = odd != b
    if parity > 0:
        answer[f"$IN[{parity}]"] = odd
    elif parity < 0:
        answer[f"$IN[{-parity}]"] = not odd
    answer[f"$IN[{abs(valid)}]"] = valid > 0
    cond, text = _active("$OUT", req)
    where = "preset pgno"
    return [
        Rule(when=cond, text=text, set=answer, after=PLC_DELAY_S, where=where, source="cell:pgno"),
        Rule(when=N.Unary("NOT", cond), text=f"NOT ({text})", set={f"$IN[{abs(valid)}]": valid < 0},
             after=PLC_DELAY_S, where=where, source="cell:pgno"),
    ]
