"""`krl debug` and the pendant's run control (issues 24, 37): the run-control engine
(engine.py: run, breakpoints, steps, pause, replay and edits; breakpoints.py; view.py: threads,
stacks, variables), the Debug Adapter Protocol adapter on top of it (session.py, with the
framing of wire.py), typed expressions (expr.py), value display (values.py) and a small DAP
client for tests and transcripts (client.py)."""
