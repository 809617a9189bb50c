"""The network partners of a run, registered once (docs/architecture.md "Network partners:
where to add one"). A partner is a net.partner.Partner subclass in its own module; adding one
is that module and one line here. The order is the order of every hub loop: settings parsed,
partners attached, polled at each IPO cycle's start, closed."""

from __future__ import annotations

from .eki import EkiPartner
from .plc import PlcPartner
from .rsi import RsiPartner
from .varproxy import VarProxyPartner

PARTNERS = (EkiPartner, VarProxyPartner, PlcPartner, RsiPartner)
