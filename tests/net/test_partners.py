"""One network-partner protocol (issue 47): every registered partner (net/partners.py) has each
operation of net/partner.py as its own (parse, attach, attached, poll, replay, close), a unique
cell-file key, its fields, and its section in docs/network.md; docs/architecture.md says where
to add one. And a partner added by its own class and one registration is parsed from the cell
file, attached, polled on the controller's clock, replayed and closed by the hub, with nothing
else changed."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

import net.partners
from net.eki import EkiPartner
from net.hub import Network
from net.partner import OPERATIONS, Partner
from net.settings import NetworkSettings, SettingsError, keys, parse_network

REPO = Path(__file__).resolve().parents[2]
NETWORK_MD = (REPO / "docs" / "network.md").read_text(encoding="utf-8")
ARCHITECTURE_MD = (REPO / "docs" / "architecture.md").read_text(encoding="utf-8")


def _missing(cls) -> list[str]:
    """The operations of the protocol `cls` does not define itself (inherited from Partner)."""
    return [op for op in OPERATIONS
            if getattr(cls, op) is getattr(Partner, op) or
            (op == "attached" and cls.attached is Partner.attached)]


@pytest.mark.parametrize("cls", net.partners.PARTNERS, ids=lambda c: c.key)
def test_each_registered_partner_is_complete(cls):
    assert issubclass(cls, Partner)
    assert not _missing(cls), f"{cls.__name__} lacks {_missing(cls)}"
    assert re.fullmatch(r"[a-z][a-z0-9_]*", cls.key)
    assert cls.fields, f"{cls.__name__}: no NetworkSettings field"
    # its docs entry: a section of docs/network.md, and its key in the cell-file example there
    assert re.search(rf"^## {re.escape(cls.docs)}\s*$", NETWORK_MD, re.M), f"docs/network.md: no '## {cls.docs}'"
    example = NETWORK_MD[NETWORK_MD.index("## The cell file"):]
    assert re.search(rf"^\s+{cls.key}:", example.split("```")[1], re.M), f"docs/network.md: no '{cls.key}:' key"
    assert f"`{cls.__name__}`" in ARCHITECTURE_MD, f"docs/architecture.md: {cls.__name__} not named"


def test_keys_and_fields_are_unique():
    ks = [c.key for c in net.partners.PARTNERS]
    fs = [f for c in net.partners.PARTNERS for f in c.fields]
    assert len(set(ks)) == len(ks) and len(set(fs)) == len(fs)
    assert not set(ks) & {"pace", "replay"}


def test_the_completeness_check_finds_a_partner_without_replay():
    class NoReplay(Partner):
        key = "x"
        fields = {"x": None}

        @classmethod
        def parse(cls, doc, base):
            return {}

        def attach(self, ctl, **cell):
            pass

        @property
        def attached(self):
            return False

        def poll(self, ctl, live):
            pass

        def close(self):
            pass

    assert _missing(NoReplay) == ["replay"]


def test_architecture_md_says_where_to_add_a_partner():
    assert "## Network partners: where to add one" in ARCHITECTURE_MD


class Echo(Partner):
    """A partner written for this test: `network: {echo: N}` counts IPO cycles; a recorded
    ``net`` event of iface ``echo`` is taken back."""

    key = "echo"
    fields = {"echo": None}
    docs = "Echo"
    log: list = []

    @classmethod
    def parse(cls, doc, base):
        if not isinstance(doc, int):
            raise SettingsError("network: echo is a number")
        return {"echo": doc}

    def attach(self, ctl, **cell):
        self.log.append(("attach", self.hub.settings.echo))

    @property
    def attached(self):
        return False

    def poll(self, ctl, live):
        self.log.append(("poll", ctl.cycle, live))

    def replay(self, ev):
        self.log.append(("replay", ev["data"]))
        self.hub.trace("echo", "in", data=ev["data"])

    def close(self):
        self.log.append(("close",))


class _Ctl:
    dt = 0.012
    cycle = 0
    time = 0.0
    trace = None
    network = None

    def message(self, text, number=None):
        pass

    @property
    def log(self):
        """The message window (the controller's event log, robot/events.py)."""
        return self


def test_a_partner_is_added_by_its_class_and_one_registration(monkeypatch, tmp_path):
    monkeypatch.setattr(net.partners, "PARTNERS", net.partners.PARTNERS + (Echo,))
    Echo.log = []
    assert "echo" in keys()
    with pytest.raises(SettingsError, match="echo is a number"):
        parse_network({"echo": "x"}, tmp_path)
    s = parse_network({"echo": 3}, tmp_path)
    assert s.echo == 3 and s.eki == {}
    recording = tmp_path / "run.jsonl"
    recording.write_text(json.dumps({"kind": "net", "t": 0.024, "iface": "echo", "dir": "in", "data": "hi"}) + "\n")
    hub = Network(NetworkSettings(tmp_path, echo=3))
    ctl = _Ctl()
    hub.attach(ctl)
    for k in range(3):
        ctl.cycle = k
        hub.cycle(ctl)
    hub.close()
    assert Echo.log == [("attach", 3), ("poll", 0, False), ("poll", 1, False), ("poll", 2, False), ("close",)]
    Echo.log = []
    replayed = Network(NetworkSettings(tmp_path, echo=3, replay=recording))
    replayed.attach(ctl)
    for k in range(3):
        ctl.cycle = k
        replayed.cycle(ctl)
    assert Echo.log == [("poll", 0, False), ("poll", 1, False), ("replay", "hi"), ("poll", 2, False)]


def test_cell_init_lines_name_the_channels_port_and_role(tmp_path):
    """`krl cell init`'s lines for EKI (EkiPartner.starter): the XML's port and who connects."""
    folder = tmp_path / "Config" / "User" / "Common" / "EthernetKRL"
    folder.mkdir(parents=True)
    (folder / "Vision.xml").write_text("<ETHERNETKRL><CONFIGURATION><EXTERNAL><TYPE>Server</TYPE><PORT>7000</PORT>"
                                       "</EXTERNAL></CONFIGURATION></ETHERNETKRL>")
    lines = EkiPartner.starter([("Vision", "R1/a.src:3"), ("Other", "R1/a.src:9")], tmp_path)
    assert lines[0] == "#   eki:"
    assert lines[1].startswith("#     Vision: {address: 127.0.0.1:7000}   # the robot connects to its partner's server;")
    assert "config Config/User/Common/EthernetKRL/Vision.xml" in lines[1]
    assert lines[2].startswith("#     Other: {address: 127.0.0.1:54600}   # opened at R1/a.src:9; no Config")
