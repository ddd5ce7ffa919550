"""``python -m poinsot.app.report [--quick] [--out DIR]``: the same as ``poinsot report``.

The command line is :mod:`poinsot.app.cli.main`'s (it owns argparse); this launcher hands it the
arguments. The CLI can also serve the live app, so this one import is exempted, by name, from
the import-linter contract that keeps the report package free of viser and the live server
(see ``ignore_imports`` in pyproject.toml). Only the ``report`` branch runs from here.
"""

import sys

from poinsot.app.cli.main import main

raise SystemExit(main(["report", *sys.argv[1:]]))
