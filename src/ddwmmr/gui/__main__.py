"""``python -m ddwmmr.gui``: see :mod:`ddwmmr.gui.cli`."""

import sys

from ddwmmr.gui.cli import main

sys.exit(main())
