"""``python -m poinsot.app.cli``: the same as ``poinsot``."""

from poinsot.app.cli.main import main

raise SystemExit(main())
