"""``python -m explorer.cli``: the ``phong-explorer`` command."""

import sys

from explorer.cli import main

sys.exit(main())
