"""``python -m ddwmmr.gui``: see :mod:`ddwmmr.cli.gui`."""

import sys

from ddwmmr.cli.gui import main

if __name__ == "__main__":
    sys.exit(main())
