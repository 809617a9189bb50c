"""The nightly: figures of each night, their history, the changes a maintainer must see.

``make nightly`` writes one dated folder ``reports/nightly/<date>/`` (recovery, growth,
conformance, check, bench and fuzz outputs, each a file of its own tool) and then runs
``python -m conformance.nightly reports/nightly``, which

1. reads that night's figures and item statuses from the folder (:mod:`.figures`),
2. appends them to the one history file ``reports/nightly/history.sqlite`` (:mod:`.history`),
3. compares the night with the one before (:mod:`.flags`): a case that newly fails, a corpus
   file or real program whose status changed, a count that moved, a speed ratio outside the
   noise band measured from the earlier nights,
4. draws each figure over time and writes ``index.html`` / ``index.md`` (:mod:`.index`).

The modules only read the files the tools wrote (JSON, CSV): they import no tool.
"""

from .index import write_index

__all__ = ["write_index"]
