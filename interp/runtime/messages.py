"""The message window of the controller: what KUKA's message functions put there
(``SET_KRLMSG``, ``SET_KRLDLG``, ``EXISTS_KRLMSG``, ``EXISTS_KRLDLG``, ``CLEAR_KRLMSG``;
KUKA System Software 8 "Programming messages", the ``MsgLib`` routines MsgNotify, MsgQuit,
MsgState, MsgDialog build on them) and the operator's answers.

Kinds (``EKRLMSGTYPE``): ``NOTIFY`` (stays until acknowledged; the program does not wait),
``STATE`` and ``WAITING`` (stay until the program clears them), ``QUIT`` (stays until the
operator acknowledges it: ``EXISTS_KRLMSG`` is TRUE until then, MsgQuit waits for it),
``DIALOG`` (stays until the operator presses one of its softkeys: ``EXISTS_KRLDLG`` is TRUE
until then and its :OUT answer is the softkey's number, 1..7).

Nobody answers in a non-interactive run (``krl run``, the reports): there a QUIT message is
acknowledged and a dialog answered with its first softkey when the program first asks, so
runs complete as before. The same QUIT message (text, module, number) acknowledged so
:data:`krl.limits.MAX_QUIT_REPEATS` times in a row, no motion planned between (the mark the
caller gives), is the controller waiting for the operator at a message the program raises again
and again (issue 85: KUKA's P00 in its program-number fault loop): :meth:`MessageWindow.operator_loop`
says so, and the caller ends the run. Under the pendant (``Runtime.interactive``) they wait for the
operator. The window holds at most :data:`krl.limits.MAX_KRL_MESSAGES` messages (the
oldest acknowledged-or-notify ones are dropped first).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from krl.limits import MAX_KRL_MESSAGES, MAX_QUIT_REPEATS

KINDS = ("NOTIFY", "STATE", "QUIT", "WAITING", "DIALOG")


@dataclass
class Message:
    """One message of the window: ``handle`` (the INT the program holds), ``kind`` (KINDS),
    ``text`` (parameters %1..%3 inserted), ``module`` and ``number`` (KrlMsg_T Modul, Nr),
    ``softkeys`` (a dialog's texts, index 0 = softkey 1), ``time`` (simulated s), ``answer``
    (the softkey number pressed, dialogs only)."""

    handle: int
    kind: str
    text: str
    module: str = ""
    number: int = 0
    softkeys: list[str] = field(default_factory=list)
    time: float = 0.0
    answer: int | None = None


class MessageWindow:
    """The messages currently shown, in the order they arrived."""

    def __init__(self, interactive: bool = False) -> None:
        self.interactive = interactive
        self.shown: list[Message] = []
        self.next_handle = 1
        #: the QUIT message acknowledged without an operator last ((kind, text, module, number),
        #: the caller's motion mark then) and how often in a row (:meth:`operator_loop`)
        self._acked: tuple | None = None
        self.repeats = 0

    @property
    def last_handle(self) -> int:
        """The handle of the last message added (0 before the first): what the fast-forward
        compares of the window (interp/runtime/idle.py, period.py, spin.py)."""
        return self.next_handle - 1

    def add(self, kind: str, text: str, module: str = "", number: int = 0,
            softkeys: list[str] | None = None, time: float = 0.0) -> Message:
        m = Message(self.next_handle, kind, text, module, number, list(softkeys or ()), time)
        self.next_handle += 1
        self.shown.append(m)
        if len(self.shown) > MAX_KRL_MESSAGES:
            drop = next((x for x in self.shown if x.kind == "NOTIFY"), self.shown[0])
            self.shown.remove(drop)
        return m

    def find(self, handle) -> Message | None:
        for m in self.shown:
            if m.handle == handle:
                return m
        return None

    def exists(self, handle: int, mark: object = None) -> bool:
        """EXISTS_KRLMSG: the message is still shown. Without an operator a QUIT message is
        acknowledged here; `mark` (the controller's motions planned so far) tells a repeat of
        the same message with no motion between (:meth:`operator_loop`)."""
        m = self.find(handle)
        if m is None:
            return False
        if not self.interactive and m.kind in ("QUIT", "NOTIFY"):
            self.shown.remove(m)
            if m.kind == "QUIT":
                key = ((m.kind, m.text, m.module, m.number), mark)
                self.repeats = self.repeats + 1 if key == self._acked else 1
                self._acked = key
            return False
        return True

    def operator_loop(self) -> str | None:
        """The run's end when the same QUIT message came back :data:`MAX_QUIT_REPEATS` times in
        a row with no motion between (module docstring), else None."""
        if self.repeats < MAX_QUIT_REPEATS or self._acked is None:
            return None
        _kind, text, module, number = self._acked[0]
        who = f" ({module} {number})" if module else ""
        return (f"the message '{text}'{who} was acknowledged {self.repeats} times in a row (no operator: at "
                f"once) and came back each time with no motion between: the controller waits for the operator "
                f"here, and acknowledging it again changes nothing")

    def dialog_answer(self, handle: int) -> tuple[bool, int | None]:
        """EXISTS_KRLDLG: (still open, the softkey number once answered). Without an operator
        the first softkey is pressed here."""
        m = self.find(handle)
        if m is None:
            return False, None
        if m.answer is None and not self.interactive:
            m.answer = 1
        if m.answer is not None:
            self.shown.remove(m)
            return False, m.answer
        return True, None

    def clear(self, handle: int) -> bool:
        """CLEAR_KRLMSG: remove the message (-99: every message); True when one was removed."""
        if handle == -99:
            had = bool(self.shown)
            self.shown = [m for m in self.shown if m.kind == "DIALOG" and m.answer is not None]
            return had
        m = self.find(handle)
        if m is None:
            return False
        self.shown.remove(m)
        return True

    # the operator's side (the pendant)
    def acknowledge(self, handle) -> None:
        """The operator acknowledges a NOTIFY or QUIT message. ValueError for a message that
        cannot be acknowledged (STATE/WAITING: the program clears them; a dialog: answer it)."""
        m = self.find(handle)
        if m is None:
            raise ValueError(f"no message {handle}")
        if m.kind not in ("NOTIFY", "QUIT"):
            raise ValueError(f"a {m.kind.lower()} message is not acknowledged by the operator")
        self.shown.remove(m)

    def answer(self, handle, key) -> None:
        """The operator presses softkey ``key`` (1..7) of a dialog. ValueError otherwise."""
        m = self.find(handle)
        if m is None or m.kind != "DIALOG":
            raise ValueError(f"no dialog {handle}")
        if not isinstance(key, int) or isinstance(key, bool) or not 1 <= key <= len(m.softkeys):
            raise ValueError(f"dialog {handle}: a softkey 1..{len(m.softkeys)}")
        if not m.softkeys[key - 1].strip():
            raise ValueError(f"dialog {handle}: softkey {key} is not shown")
        m.answer = key


def format_text(text: str, params: list[str]) -> str:
    """``%1``..``%3`` of a message text replaced by its parameters (KrlMsgPar_T)."""
    out = text
    for i, p in enumerate(params[:3], start=1):
        out = out.replace(f"%{i}", p)
    return out


__all__ = ["KINDS", "Message", "MessageWindow", "format_text"]
