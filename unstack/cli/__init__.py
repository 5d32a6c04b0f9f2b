"""The ``unstack`` command line: thin click commands over the library.

Every user mistake becomes one line on standard error and exit code 2.
"""

from unstack.cli.main import cli, main

__all__ = ["cli", "main"]
