"""``python -m cerebx`` is the ``cerebx`` command."""

from cerebx.cli import console

console()
