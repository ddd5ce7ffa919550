"""The command line: `poinsot` and its subcommands (`main.py` builds the one parser; each command
declares its options beside its implementation), the converters of its arguments and its one-line
error boundary."""
