"""``python -m poinsot.physics.fuzz --cases N``: see :mod:`poinsot.physics.fuzz`."""

import sys

from poinsot.physics.fuzz.summary import main

sys.exit(main())
