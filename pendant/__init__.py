"""`krl pendant`: a virtual smartPAD in the browser (issue 36; docs/pendant.md).

engine.py drives the one run-control engine of ``krl debug`` in-process; state.py reads what
the page shows; touchup.py writes a touched-up point; security.py holds the token, the Origin
check and the workspace confinement; server.py is the web application (Starlette on uvicorn,
websockets); cli.py the command. client.py is a client of the command (start it, speak its
websocket protocol, Chromium's flags) for bench.py, the benchmark, and the tests. The page is
built from web/ into static/ (``make pendant-assets``).
"""
