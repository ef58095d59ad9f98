"""``python -m allanite`` — the same as the ``allanite`` command."""

import sys

from .cli import main

sys.exit(main())
