"""RSI 2 (KUKA.RobotSensorInterface 2.x with KUKA.Ethernet RSI XML, KR C2, KSS 5.x): the signal
flow a KRL program builds object by object with the ``ST_`` functions, onto the model of
net/rsicontext.py, run by net/rsi.py's cycle (docs/network.md "RobotSensorInterface", RSI 2).

Where RSI 3 and later read the objects from a context file, RSI 2 creates them from KRL; each
``ST_`` function returns an RSIERR number (RSIOK = 0) and gives the new object's handle in its
first argument:

* ``ST_ETHERNET(h :OUT, container, "config.xml")``: the ETHERNET object; its configuration is
  KUKA's ROOT document as for RSI 3 (``CONFIG``, ``SEND``, ``RECEIVE``; RSI 2's
  ``CONFIG/PROTOCOL`` UDP or TCP), found as the controller keeps it, in ``C:\\KRC\\ROBOTER\\INIT``
  (the backup's ``Roboter/Init``; ROS-Industrial's KR_C2 README: "Copy the ros_rsi_ethernet.xml
  file to C:\\KRC\\ROBOTER\\Init"), beside the program, or the cell file's ``rsi: {ethernet:}``
  (or ``config:`` naming an ETHERNET configuration). Late packets allowed in a row: 100, as the
  RSI 3 ETHERNET object's Timeout (its RSI 2 parameters are set by number and not simulated).
* ``ST_AXISCORR(h :OUT, container)``: an AXISCORR; ``ST_SETPARAM(h, n, value)`` parameter 1 is
  the integration mode (0 absolute, 1 relative), 2..13 the lower limits of A1..A6, E1..E6,
  14..25 the upper ones (ROS-Industrial's KR_C2 ``ros_rsi.src``; msstachnik's KCT
  ``kctrsiclient.src`` sets the same numbers for A1..A6).
* ``ST_PATHCORR(h :OUT, container)``: a POSCORR; parameters 1..6 the lower limits of X, Y, Z,
  A, B, C, 7..12 the upper ones (KCT's ``kctrsiclient.src``: "range X" 1 and 7, ...).
* ``ST_NEWLINK(hOut, outIdx, hIn, inIdx)``: input inIdx of hIn is output outIdx of hOut
  (indices from 1; ETHERNET output n is the configuration's ``INDX="n"``).
* ``ST_ON()``: the sensor mode on, the integration mode the correction objects' parameter 1
  says (relative when unset, as RSI_ON's default); ``ST_ON1(#frame, n)`` the same with the
  Cartesian correction in #WORLD, #BASE or #TCP (n not modelled); ``ST_SKIPSENS()``: the robot
  follows the sensor only, until an error ends it (neither program of the corpus creates an
  object that ends it); ``ST_OFF()``: the sensor mode off; ``ST_DELOBJ(h)``, ``ST_RESET()``.
* Any other object (``ST_DIGIN``, ``ST_MAP2DIGOUT``, ``ST_COROB``: the TCP "CoRob" partner of
  Ethernet RSI XML) gets a handle and is reported once as not simulated; its outputs read 0.

A flow holds at most ``MAX_RSI_OBJECTS`` objects (as a context file): one more is RSINOMEM.
"""

from __future__ import annotations

from pathlib import Path

from krl.limits import MAX_RSI_OBJECTS

from .rsicontext import Context, RsiConfigError, RsiObject, read_ethernet

RSI2 = "RSI 2"
#: the ST_ functions that create an object, and the object's type in the model
CREATES = {"ST_ETHERNET": "ETHERNET", "ST_AXISCORR": "AXISCORR", "ST_PATHCORR": "POSCORR",
           "ST_DIGIN": "DIGIN", "ST_MAP2DIGOUT": "MAP2DIGOUT", "ST_COROB": "COROB"}
AXIS_LIMITS = ("A1", "A2", "A3", "A4", "A5", "A6", "E1", "E2", "E3", "E4", "E5", "E6")
CART_LIMITS = ("X", "Y", "Z", "A", "B", "C")
MAX_PARAM = 64             # parameter numbers of ST_SETPARAM
ETHERNET_TIMEOUT = 100     # late packets in a row (docs/network.md, Decisions: RSI 2)
FRAMES = {"WORLD": "0", "BASE": "Base", "TCP": "Tool", "TOOL": "Tool"}


def param_name(typ: str, n: int) -> str | None:
    """The model's name of ST_SETPARAM parameter `n` of an object of type `typ` (module
    docstring), None for a number the simulator does not know."""
    if typ == "AXISCORR":
        if n == 1:
            return "IntegrationMode"
        if 2 <= n <= 13:
            return "LowerLim" + AXIS_LIMITS[n - 2]
        if 14 <= n <= 25:
            return "UpperLim" + AXIS_LIMITS[n - 14]
    if typ == "POSCORR":
        if 1 <= n <= len(CART_LIMITS):
            return "LowerLim" + CART_LIMITS[n - 1]
        if len(CART_LIMITS) < n <= 2 * len(CART_LIMITS):
            return "UpperLim" + CART_LIMITS[n - 1 - len(CART_LIMITS)]
    return None


def init_folders(program: Path | None, backup: Path | None) -> list[Path]:
    """Where RSI 2 looks for an ETHERNET configuration: the backup's ``Roboter/Init`` (KR C2's
    ``C:\\KRC\\ROBOTER\\INIT``: ``Roboter/Init``, ``KRC/Roboter/Init`` or ``C/KRC/Roboter/Init``
    under the backup's root or beside its KRC folder; folder names compare without case), then
    beside the program."""
    out = []
    if backup is not None:
        tops = [[backup], [backup, "KRC"], [backup, "C", "KRC"]]
        if backup.name.lower() == "krc":         # the root is the archive's KRC folder: C/ beside it
            tops.append([backup.parent, "C", "KRC"])
        for top in tops:
            p = _folder(top[0], *top[1:], "Roboter", "Init")
            if p is not None:
                out.append(p)
    if program is not None:
        out.append(program.parent)
    return out


def _folder(base: Path, *parts: str) -> Path | None:
    p = Path(base)
    for part in parts:
        if not p.is_dir():
            return None
        nxt = p / part
        if not nxt.is_dir():
            nxt = next((q for q in sorted(p.iterdir()) if q.is_dir() and q.name.lower() == part.lower()), None)
            if nxt is None:
                return None
        p = nxt
    return p if p.is_dir() else None


def find_ethernet(name: str, folders: list[Path]) -> Path | None:
    """The file `name` (without a folder; names compare without case) in `folders`."""
    name = Path(name.replace("\\", "/")).name
    for f in folders:
        if not f.is_dir():
            continue
        p = f / name
        if p.is_file():
            return p
        for q in sorted(f.iterdir()):
            if q.is_file() and q.name.lower() == name.lower():
                return q
    return None


class SignalFlow:
    """The objects an RSI 2 program created, as a :class:`Context` net/rsi.py runs. Handles
    count from 1 in creation order."""

    def __init__(self) -> None:
        self.ctx = Context("ST", RSI2, None, {}, "", None)
        self.next = 1

    def create(self, typ: str, **params) -> RsiObject | None:
        if len(self.ctx.objects) >= MAX_RSI_OBJECTS:      # as a context file's (docs/security.md)
            return None
        obj = RsiObject(typ, str(self.next), {k: str(v) for k, v in params.items()})
        self.next += 1
        self.ctx.objects[obj.id] = obj
        return obj

    def ethernet(self, obj: RsiObject, config: Path) -> None:
        """Make `obj` the flow's ETHERNET object with the configuration `config` (raises
        :class:`RsiConfigError`)."""
        self.ctx.ethernet = read_ethernet(config)
        self.ctx.ethernet_id = obj.id
        self.ctx.path = config
        obj.params.setdefault("ConfigFile", config.name)
        obj.params.setdefault("Timeout", str(ETHERNET_TIMEOUT))

    def obj(self, handle) -> RsiObject | None:
        try:
            return self.ctx.objects.get(str(int(handle)))
        except (TypeError, ValueError):
            return None


__all__ = ["CREATES", "RSI2", "RsiConfigError", "SignalFlow", "find_ethernet", "init_folders", "param_name"]
