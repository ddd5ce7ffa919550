"""``python -m poinsot.physics.tools.fuzz --cases N``: see :mod:`poinsot.physics.tools.fuzz`."""

import sys

from poinsot.physics.tools.fuzz.summary import main

sys.exit(main())
