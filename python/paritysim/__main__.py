"""``python -m paritysim``: the ``paritysim`` command line."""

from .cli import main

raise SystemExit(main())
