"""``python -m vibroimpact``: the same as the ``vibroimpact`` command."""

import sys

from vibroimpact.cli import main

sys.exit(main())
