"""python3 -m bumpbake.dask bake ... --scheduler ADDRESS (bumpbake.dask._cli)."""

import sys

from ._cli import main

if __name__ == "__main__":
    sys.exit(main())
