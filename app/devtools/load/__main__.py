"""``python -m poinsot.app.devtools.load [--phase soak storm stall flood] [--clients N] [--seconds
S]``."""

from poinsot.app.devtools.load.cli import main

raise SystemExit(main())
