"""``python -m nmsm``: the ``nmsm`` command line (for environments whose scripts folder is not on PATH)."""

import sys

from nmsm.cli import main

sys.exit(main())
