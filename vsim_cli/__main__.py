"""``python -m vsim_cli``: the ``vsim`` command."""

import sys

from vsim_cli.executable import main

sys.exit(main())
