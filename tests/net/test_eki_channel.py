"""An EKI channel's element memory without sockets (net/eki.py): XML, fixed and variable binary
streams, FIFO and LIFO, arrays, locking, clearing, the send structure. The expected values are
what the EthernetKRL manual describes for each function."""

from __future__ import annotations

import xml.etree.ElementTree as ET

from net.eki import Channel
from net.ekiconfig import parse_config
from net.hub import Network, NullSink
from net.xmlsafe import XmlRefused


def channel(body: str, internal: str = "") -> tuple[Channel, NullSink]:
    xml = f"""<ETHERNETKRL><CONFIGURATION><EXTERNAL><TYPE>Client</TYPE></EXTERNAL>
      <INTERNAL><PORT>54600</PORT><ALIVE Set_Flag="3"/>{internal}</INTERNAL></CONFIGURATION>{body}</ETHERNETKRL>"""
    sink = NullSink()
    net = Network(sink=sink)
    ch = Channel(net, parse_config(xml.encode(), "T"))
    ch.connected_event()
    return ch, sink


def feed(ch: Channel, data: bytes) -> list:
    out = []
    for msg in ch.data_event(data):             # as the hub hands them over (net/hub.py)
        if isinstance(msg, XmlRefused):
            ch.refused(msg)
        else:
            out += ch.message(msg)
    return out


XML = """<RECEIVE><XML><ELEMENT Tag="R/V" Type="REAL" Set_Flag="7"/><ELEMENT Tag="R/P" Type="FRAME"/>
  <ELEMENT Tag="R/I/@N" Type="INT"/></XML></RECEIVE>
  <SEND><XML><ELEMENT Tag="S/Pos"/><ELEMENT Tag="S/Msg"/><ELEMENT Tag="S/A/@X"/></XML></SEND>"""


def test_xml_elements_fifo_flags_and_counter():
    ch, sink = channel(XML)
    assert sink.flags == {3: True}                        # ALIVE Set_Flag follows the connection
    sets = feed(ch, b"<R><V>1.5</V><I N='4'/></R><R><V>2.5</V></R>")
    assert sets == [("flag", 7), ("flag", 7)]             # the element's Set_Flag, once per arrival
    st, err = ch.check("R/V")
    assert err is None and st.buff == 2 and st.counter == 1
    vals, st, err = ch.get("R/V")
    assert vals == ["1.5"] and st.buff == 1 and st.read == 1 and st.counter == 1
    vals, st, err = ch.get("R/V")
    assert vals == ["2.5"] and st.counter == 2
    vals, st, err = ch.get("R/V")
    assert err is not None and err.number == 15 and st.msg_no == 15
    vals, st, err = ch.get("R/I/@N")
    assert vals == ["4"]


def test_lifo_arrays_frames_and_clear():
    ch, _ = channel(XML, '<BUFFERING Mode="LIFO" Limit="3"/>')
    feed(ch, b"".join(f"<R><V>{i}</V></R>".encode() for i in range(5)))
    assert ch.async_no == 1280                            # the 4th and 5th found the memory full
    vals, st, _ = ch.get("R/V", 5)                        # an array getter takes up to its length
    assert vals == ["2", "1", "0"] and st.read == 3 and st.buff == 0 and st.msg_no == 1280
    feed(ch, b'<R><P X="1" Y="2" Z="3" A="4" B="5" C="6"/></R>')
    vals, _, _ = ch.get("R/P")
    assert vals == [{"X": "1", "Y": "2", "Z": "3", "A": "4", "B": "5", "C": "6"}]
    feed(ch, b"<R><V>9</V><I N='1'/></R>")
    ch.clear_buffer("R")
    assert ch.check("R/V")[0].buff == 0 and ch.check("R/I/@N")[0].buff == 0


def test_lock_holds_messages_until_unlock():
    ch, _ = channel(XML)
    ch.lock()
    feed(ch, b"<R><V>1</V></R>")
    assert ch.check("R/V")[0].buff == 0
    ch.unlock()
    assert ch.check("R/V")[0].buff == 1


def test_send_builds_the_part_under_a_path():
    ch, _ = channel(XML)
    sent = []
    ch.hub.eki_send = lambda c, payload: sent.append(payload)
    ch.set_value("S/A/@X", "1.25")
    ch.set_value("S/Msg", "hello")
    assert ch.send("S")[1] is None
    doc = ET.fromstring(sent[-1])
    assert doc.tag == "S" and doc.find("A").get("X") == "1.25" and doc.find("Msg").text == "hello"
    # a part is sent inside its ancestors, its siblings left out (the EthernetKRL manual's
    # EKI_Send("Channel_1", "Robot/ActPos") sends <Robot><ActPos X=".."/></Robot>)
    assert ch.send("S/A")[1] is None
    doc = ET.fromstring(sent[-1])
    assert doc.tag == "S" and [c.tag for c in doc] == ["A"] and doc.find("A").get("X") == "1.25"
    assert ch.send("<Direct/>")[1] is None and sent[-1] == b"<Direct/>"
    st, err = ch.set_value("S/Nope", "1")
    assert err.number == 16
    ch.disconnected_event("closed")
    st, err = ch.send("S")
    assert err.number == 10 and not st.connected


def test_fixed_and_variable_binary_streams():
    fixed, _ = channel('<RECEIVE><RAW><ELEMENT Tag="Buffer" Type="BYTE" Size="4" Set_Flag="2"/></RAW></RECEIVE>')
    assert feed(fixed, b"abcdef") == [("flag", 2)]        # one record of 4 bytes, 2 bytes wait
    feed(fixed, b"gh")
    assert fixed.get("Buffer", 2)[0] == ["abcd", "efgh"]
    var, _ = channel('<RECEIVE><RAW><ELEMENT Tag="Buffer" Type="STREAM" EOS="13,10" Size="8"/></RAW></RECEIVE>')
    feed(var, b"one\r\ntwo\r\n" + b"x" * 20)
    vals, st, _ = var.get("Buffer", 5)
    assert vals == ["one", "two"]
    assert st.msg_no == 1536                              # a record past Size without its end string
