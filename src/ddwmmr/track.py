"""``python -m ddwmmr.track``: see :mod:`ddwmmr.cli.track`."""

import sys

from ddwmmr.cli.track import main

if __name__ == "__main__":
    sys.exit(main())
