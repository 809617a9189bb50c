"""The controller's logbook (issue 75): a KUKA controller archive's event logs read, tied to its code.

* :mod:`krl.logbook.evtx` -- one ``KrcLog*.evt`` (Windows EVTX) read with python-evtx;
* :mod:`krl.logbook.record` -- a KUKA record (the ``LS`` document: source, module, number, key,
  parameters) and the logbook of a path (one log, a ``Log Files`` folder, an archive);
* :mod:`krl.logbook.links` -- parameters that name a program module or its variable, resolved to
  the archive's file and the variable's declaration through the front end;
* :mod:`krl.logbook.summary` -- ``krl log summary``: messages by number and module, the programs
  named, the operator's actions as a timeline.

docs/log.md describes the commands and the record; docs/security.md the limits.
"""
