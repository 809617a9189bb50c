"""`krl debug`: a Debug Adapter Protocol server over the interpreters (issue 24): framing
(wire.py), typed expressions (expr.py), value display (values.py), the session (session.py)
and a small client for tests and transcripts (client.py)."""
