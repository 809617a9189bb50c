"""KRL tools: grammar recovery, front end, interpreters and a simulated KUKA controller."""

__version__ = "0.1.0"
