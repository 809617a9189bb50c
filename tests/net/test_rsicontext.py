"""RSI contexts of both generations (net/rsicontext.py, issue 50): every published context of
the corpus repositories read onto one model, KUKA's ETHERNET template as shipped, and clear
errors for documents outside the format.

The published files are in tests/net/configs/published/ (the corpus on disk holds only the
KRL; each fixture's first comment names its repository, path and commit, and what was left
out). The expected values below were read from the published files by hand, not from the
reader."""

from __future__ import annotations

from pathlib import Path

import pytest

from net.hub import NullSink
from net.rsi import Rsi
from net.rsicontext import RSI3, RSI45, IMPLIED, RsiConfigError, find_context, load_context, read_ethernet
from net.settings import SettingsError, parse_network

from .helpers import CONFIGS

PUB = CONFIGS / "published"


def links(ctx, obj_type):
    """{input n: RECEIVE tag} of the first object of `obj_type`, following LIMIT objects."""
    o = ctx.of_type(obj_type)[0]
    by_indx = {e.indx: e.tag for e in ctx.ethernet.receive if not e.internal}
    out = {}
    for i, (src, oi) in o.inputs.items():
        s = ctx.obj(src)
        while s.type == "LIMIT":
            src, oi = s.inputs[1]
            s = ctx.obj(src)
        assert s.type == "ETHERNET"
        out[i] = by_indx.get(oi)
    return out


AK = {i: f"AK.A{i}" for i in range(1, 7)}
RK = {i + 1: f"RKorr.{k}" for i, k in enumerate("XYZABC")}

# (context file, generation, object types, ETHERNET configuration, correction links, STOP's tag)
PUBLISHED = [
    ("ros_industrial_kr_c4/ros_rsi.rsix", RSI45, {"AXISCORR", "ETHERNET", "AXISCORRMON"}, "ros_rsi_ethernet.xml",
     ("AXISCORR", AK), None),
    ("ros_industrial_kr_c4/RSI_Ethernet.rsix", RSI45,
     {"DIGIN", "DIGOUT", "SOURCE", "POSCORR", "MAP2DIGOUT", "MAP2SEN_PREA", "ETHERNET"}, "RSI_EthernetConfig.xml",
     ("POSCORR", RK), None),
    ("fzi_kr_c5/ros_rsi.rsix", RSI45, {"ETHERNET", "AXISCORR", "AXISCORRMON", "GEARTORQUE", "OV_PRO", "STATUS"},
     "ros_rsi_ethernet.xml", ("AXISCORR", AK), None),
    ("fzi_kr_c4/ros_rsi.rsi.xml", RSI3, {"ETHERNET", "AXISCORR", "AXISCORRMON", "GEARTORQUE", "OV_PRO", "STATUS"},
     "ros_rsi_ethernet.xml", ("AXISCORR", AK), None),
    ("wingljj/PoseTrack.rsix", RSI45, {"ETHERNET", "LIMIT", "POSCORR", "POSCORRMON"}, "PoseTrack_ethernet.xml",
     ("POSCORR", RK), None),
    ("wingljj_legacy/PoseTrack.rsi.xml", RSI3, {"ETHERNET", "LIMIT", "POSCORR", "POSCORRMON"},
     "PoseTrack_ethernet.xml", ("POSCORR", RK), None),
    ("kroshu_kss/rsi_joint_pos.rsix", RSI45, {"ETHERNET", "AXISCORR", "STOP", "AXISCORRMON", "MONITOR"},
     "rsi_ethernet.xml", ("AXISCORR", AK), "Stop"),
    ("kroshu_kss/rsi_gpio_joint_pos.rsix", RSI45,
     {"ETHERNET", "AXISCORR", "STOP", "AXISCORRMON", "DIGOUT", "DIGIN", "MAP2DIGOUT"}, "rsi_gpio_ethernet.xml",
     ("AXISCORR", AK), "Stop"),
    ("adamleon/RSIAxisCorrTest.rsi.xml", RSI3, {"ETHERNET", "AXISCORR", "AXISCORRMON"}, "RSIAxisCorrTestConfig.xml",
     ("AXISCORR", AK), None),
    ("alexeiovcharov/Painter_RSI.xml", IMPLIED, {"ETHERNET", "AXISCORR"}, "Painter_RSI.xml", ("AXISCORR", AK), None),
    # the project's earlier fixture, written from the SDK's KSS < 8.5 RSI 3 context
    ("ros_industrial_kr_c4/ros_rsi.rsi.xml", RSI3, {"ETHERNET", "AXISCORR", "AXISCORRMON"}, "ros_rsi_ethernet.xml",
     ("AXISCORR", AK), None),
    ("kroshu/rsi_joint_pos.rsi.xml", RSI3, {"ETHERNET", "AXISCORR", "AXISCORRMON", "STOP"}, "rsi_ethernet.xml",
     ("AXISCORR", AK), "Stop"),
]


@pytest.mark.parametrize("rel,generation,types,ethernet,corr,stop", PUBLISHED, ids=[p[0] for p in PUBLISHED])
def test_published_contexts(rel, generation, types, ethernet, corr, stop):
    ctx = load_context(PUB / rel if (PUB / rel).exists() else CONFIGS / rel, "x")
    assert ctx.generation == generation
    assert {o.type for o in ctx.objects.values()} == types
    assert ctx.ethernet.path.name == ethernet
    assert links(ctx, corr[0]) == corr[1]
    if stop:
        assert links(ctx, "STOP") == {1: stop}
    else:
        assert not ctx.of_type("STOP")


def test_rsi4_indices_count_from_zero():
    """The same SDK context in both generations gives the same model: RSI 3's OutIdx 2 and
    RSI 4's OutIdx 1 both take AK.A1 (INDX 2)."""
    r3 = load_context(CONFIGS / "kroshu" / "rsi_joint_pos.rsi.xml", "x")
    r4 = load_context(PUB / "kroshu_kss" / "rsi_joint_pos.rsix", "x")
    for ctx in (r3, r4):
        ax = ctx.of_type("AXISCORR")[0]
        assert ax.inputs[1][1] == 2 and ax.inputs[6][1] == 7
        assert ctx.of_type("STOP")[0].inputs[1][1] == 1


def test_the_ethernet_object_sends_what_its_inputs_link():
    """FZI's KR C5 context links GearTorque to channels 1..6, Status and OV_PRO to 7 and 8."""
    ctx = load_context(PUB / "fzi_kr_c5" / "ros_rsi.rsix", "x")
    eth = ctx.eth
    assert eth.id == "RSI"
    assert eth.inputs[1] == ("GearTorque_1", 1) and eth.inputs[7] == ("Status_1", 1) and eth.inputs[8] == ("OV_PRO_1", 1)
    assert ctx.ethernet.sentype == "KukaRsiDriver" and ctx.ethernet.port == 49152
    assert [e.tag for e in ctx.ethernet.send if not e.internal][:2] == ["GearTorque.A1", "GearTorque.A2"]


def test_kuka_template_as_shipped():
    """KUKA's RSI_EthernetConfig.xml: INTERNAL elements in RECEIVE too (DEF_EStr, DEF_Tech.T2),
    FREE and DiO channels, every documented TYPE."""
    cfg = read_ethernet(PUB / "ros_industrial_kr_c4" / "RSI_EthernetConfig.xml")
    internal = [(e.tag, e.type) for e in cfg.receive if e.internal]
    assert internal == [("DEF_EStr", "STRING"), ("DEF_Tech.T2", "DOUBLE")]
    assert [e.indx for e in cfg.receive if not e.internal] == [1, 2, 3, 4, 5, 6, 7, 8]
    assert {e.type for e in cfg.send} == {"DOUBLE", "LONG", "BOOL"}
    assert [e.holdon for e in cfg.receive if not e.internal] == [True] * 8
    assert cfg.onlysend is False and cfg.sentype == "ImFree"


BAD = [
    ('<ELEMENT TAG="AK.A1" TYPE="FLOAT" INDX="1"/>', "RECEIVE element 'AK.A1': TYPE 'FLOAT'"),
    ('<ELEMENT TAG="AK.A1" TYPE="DOUBLE" INDX="first"/>', "RECEIVE element 'AK.A1': INDX 'first' is neither INTERNAL"),
    ('<ELEMENT TAG="AK.A1" TYPE="DOUBLE" INDX="65"/>', "RECEIVE element 'AK.A1': INDX 65 outside 1..64"),
    ('<ELEMENT TAG="AK.A1" TYPE="DOUBLE" INDX="1" HOLDON="yes"/>', "RECEIVE element 'AK.A1': HOLDON 'yes'"),
]


@pytest.mark.parametrize("element,message", BAD)
def test_outside_the_format_names_file_and_element(tmp_path, element, message):
    p = tmp_path / "bad_ethernet.xml"
    p.write_text(f"<ROOT><CONFIG><PORT>49152</PORT></CONFIG><RECEIVE><ELEMENTS>{element}</ELEMENTS></RECEIVE></ROOT>")
    with pytest.raises(RsiConfigError) as e:
        read_ethernet(p)
    assert "bad_ethernet.xml" in str(e.value) and message in str(e.value)


def test_other_documents_get_a_clear_error(tmp_path):
    p = tmp_path / "x.rsi.xml"
    p.write_text("<Settings><RSIObject/></Settings>")
    with pytest.raises(RsiConfigError, match=r"x.rsi.xml: root element <Settings>"):
        load_context(p, "x")
    p.write_text("<ROOT><SEND/></ROOT>")
    with pytest.raises(RsiConfigError, match="x.rsi.xml: no CONFIG element"):
        load_context(p, "x")
    p.write_text("<ROOT><CONFIG><PORT>49152</PORT><ONLYSEND>maybe</ONLYSEND></CONFIG></ROOT>")
    with pytest.raises(RsiConfigError, match="CONFIG/ONLYSEND 'MAYBE'"):
        load_context(p, "x")
    p.write_text('<RSIObjects><RSIObject ObjType="AXISCORR" ObjID="A"><Inputs><Input InIdx="1" OutObjID="NOPE" '
                 'OutIdx="1"/></Inputs></RSIObject><RSIObject ObjType="ETHERNET" ObjID="E"><Parameters><Parameter '
                 'Name="ConfigFile" ParamValue="e.xml"/></Parameters></RSIObject></RSIObjects>')
    (tmp_path / "e.xml").write_text("<ROOT><CONFIG><PORT>1</PORT></CONFIG></ROOT>")
    with pytest.raises(RsiConfigError, match="object A input 1 is linked to 'NOPE'"):
        load_context(p, "x")
    q = tmp_path / "ros_rsi.rsi"
    q.write_text("<rSIModel/>")
    with pytest.raises(RsiConfigError, match="RSI Visual's editor file"):
        load_context(q, "x")


def test_find_context_of_both_generations(tmp_path):
    prog = tmp_path / "prog.src"
    prog.write_text("DEF prog()\nEND\n")
    (tmp_path / "PoseTrack.rsix").write_text("<RsiContext/>")
    assert find_context("PoseTrack", prog, None).name == "PoseTrack.rsix"
    assert find_context("PoseTrack.rsi", prog, None).name == "PoseTrack.rsix"
    sens = tmp_path / "backup" / "KRC" / "Config" / "User" / "Common" / "SensorInterface"
    sens.mkdir(parents=True)
    (sens / "ros_rsi.rsi.xml").write_text("<RSIObjects/>")
    assert find_context("ros_rsi.rsi", None, tmp_path / "backup").name == "ros_rsi.rsi.xml"
    assert find_context("missing", prog, tmp_path / "backup") is None


def test_the_ethernet_configuration_in_a_folder_beside(tmp_path):
    """FZI's repository keeps ros_rsi_ethernet.xml in krl/Common beside krl/KR_C4 and
    krl/KR_C5; the context finds it there (and says where it looked when it is nowhere)."""
    for sub in ("KR_C4", "Common"):
        (tmp_path / sub).mkdir()
    ctx = tmp_path / "KR_C4" / "ros_rsi.rsi.xml"
    ctx.write_bytes((PUB / "fzi_kr_c4" / "ros_rsi.rsi.xml").read_bytes())
    with pytest.raises(RsiConfigError, match="ConfigFile ros_rsi_ethernet.xml not found"):
        load_context(ctx, "ros_rsi")
    (tmp_path / "Common" / "ros_rsi_ethernet.xml").write_bytes((PUB / "fzi_kr_c4" / "ros_rsi_ethernet.xml").read_bytes())
    assert load_context(ctx, "ros_rsi").ethernet.path == tmp_path / "Common" / "ros_rsi_ethernet.xml"


class _Hub:
    """The little of net/hub.py an Rsi object reads outside a run."""
    settings = program = backup = ctl = None
    sink = NullSink()

    def __init__(self):
        self.messages = []

    def trace(self, *a, **k):
        pass

    def net_message(self, text, number=None):
        self.messages.append(text)


def test_toolbox_blocks_in_the_signal_flow(tmp_path):
    """RSI 4/5 context whose POSCORR X comes through MULTI(ch1, ch2), Y through SUM(ch1, Value
    0.5), Z through LIMIT(ch3) with the blueprint's default limits (+-10) and A through a
    SUB of Division(ch1, ch2) and ch2; relative mode adds each answer once."""

    (tmp_path / "e.xml").write_text(
        '<ROOT><CONFIG><PORT>49152</PORT></CONFIG><RECEIVE><ELEMENTS>'
        '<ELEMENT TAG="P.a" TYPE="DOUBLE" INDX="1"/><ELEMENT TAG="P.b" TYPE="DOUBLE" INDX="2"/>'
        '<ELEMENT TAG="P.c" TYPE="DOUBLE" INDX="3"/><ELEMENT TAG="DEF_EStr" TYPE="STRING" INDX="INTERNAL"/>'
        '</ELEMENTS></RECEIVE></ROOT>')
    (tmp_path / "c.rsix").write_text(
        '<RsiContext><RsiObjects>'
        '<RsiObject ObjType="Ethernet" ObjId="E"><Parameters><Parameter Name="ConfigFile" ParamValue="e.xml"/></Parameters></RsiObject>'
        '<RsiObject ObjType="MULTI" ObjId="M"><Inputs><Input InIdx="0" OutObjId="E" OutIdx="0"/><Input InIdx="1" OutObjId="E" OutIdx="1"/></Inputs></RsiObject>'
        '<RsiObject ObjType="SUM" ObjId="S"><Inputs><Input InIdx="0" OutObjId="E" OutIdx="0"/></Inputs>'
        '<Parameters><Parameter Name="Value" ParamValue="0.5"/></Parameters></RsiObject>'
        '<RsiObject ObjType="Limit" ObjId="L"><Inputs><Input InIdx="0" OutObjId="E" OutIdx="2"/></Inputs></RsiObject>'
        '<RsiObject ObjType="Division" ObjId="D"><Inputs><Input InIdx="0" OutObjId="E" OutIdx="0"/><Input InIdx="1" OutObjId="E" OutIdx="1"/></Inputs></RsiObject>'
        '<RsiObject ObjType="SUB" ObjId="B"><Inputs><Input InIdx="0" OutObjId="D" OutIdx="0"/><Input InIdx="1" OutObjId="E" OutIdx="1"/></Inputs></RsiObject>'
        '<RsiObject ObjType="PosCorr" ObjId="P"><Inputs><Input InIdx="0" OutObjId="M" OutIdx="0"/>'
        '<Input InIdx="1" OutObjId="S" OutIdx="0"/><Input InIdx="2" OutObjId="L" OutIdx="0"/><Input InIdx="3" OutObjId="B" OutIdx="0"/></Inputs></RsiObject>'
        '</RsiObjects></RsiContext>')
    hub = _Hub()
    rsi = Rsi(hub)
    rsi.ctx = load_context(tmp_path / "c.rsix", "c")
    rsi.mode = "RELATIVE"
    for n, ipoc in enumerate((12, 24)):
        rsi.expect, rsi.recent = [ipoc], [ipoc]
        rsi.answer(f'<Sen Type="ImFree"><P a="3" b="2" c="25"/><EStr>step {n}</EStr><IPOC>{ipoc}</IPOC></Sen>'.encode())
    # two answers: X 2*(3*2), Y 2*(3+0.5), Z 2*10 (limited), A 2*(3/2-2)
    assert rsi.cart.tolist() == [12.0, 7.0, 20.0, -1.0, 0.0, 0.0]
    assert hub.messages == ["RSI sensor: step 0", "RSI sensor: step 1"]


def test_cell_file_names_the_ethernet_configuration(tmp_path):

    s = parse_network({"rsi": {"config": "ctx/ros_rsi.rsix", "ethernet": "Common/ros_rsi_ethernet.xml"}}, tmp_path)
    assert s.rsi.config == tmp_path / "ctx" / "ros_rsi.rsix"
    assert s.rsi.ethernet == tmp_path / "Common" / "ros_rsi_ethernet.xml"
    with pytest.raises(SettingsError, match="without '..'"):
        parse_network({"rsi": {"ethernet": "../x.xml"}}, tmp_path)
    with pytest.raises(SettingsError, match="unknown key 'ethernet'"):
        parse_network({"eki": {"CH": {"config": "a.xml", "ethernet": "b.xml"}}}, tmp_path)
