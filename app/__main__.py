"""`python -m app`: the `krl` command (named so in its help and messages)."""

from app import main

main(prog_name="krl")
