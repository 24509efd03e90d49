"""``python -m grainview``: the ``grainview`` command (:mod:`grainview.app.cli`)."""

import sys

from grainview.app.cli import main

sys.exit(main())
