"""``python -m gearsym.cli``: the ``gearsym`` command without the installed console script."""
import sys

from . import main

sys.exit(main())
