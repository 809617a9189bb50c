"""The runtime shared by the tree interpreter and the VM (issue 6, docs/architecture.md
"Interpreters"): values, memory, conversions, built-ins, system variables, errors, the
context stack with interrupts, the advance-run rules, the motion interface and the
cooperative scheduler. Everything semantic lives here; an interpreter only decides how
to step."""
