"""``python -m cerebx`` is the ``cerebx`` command."""

import sys

from cerebx.cli import main

sys.exit(main())
