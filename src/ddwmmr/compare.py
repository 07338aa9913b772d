"""``python -m ddwmmr.compare``: see :mod:`ddwmmr.cli.compare`."""

import sys

from ddwmmr.cli.compare import main

if __name__ == "__main__":
    sys.exit(main())
