"""``python -m elastokin``: the ``vsim`` command."""

import sys

from elastokin.cli.executable import main

sys.exit(main())
