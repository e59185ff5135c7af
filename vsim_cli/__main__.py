"""``python -m vsim_cli``: the ``vsim`` command."""

import sys

from vsim_cli.main import main

sys.exit(main())
