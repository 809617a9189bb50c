"""`python -m krl.cli`: the `krl` command."""

from krl.cli import main

main()
