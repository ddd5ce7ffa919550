"""``python -m poinsot.app.load [--phase soak storm stall flood] [--clients N] [--seconds S]``."""

from poinsot.app.load.cli import main

raise SystemExit(main())
