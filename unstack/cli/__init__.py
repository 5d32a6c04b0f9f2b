"""The ``unstack`` command line: thin click commands over the library.

The commands live in :mod:`unstack.cli.main` (entry point ``unstack``, or
``python -m unstack``). Every user mistake becomes one line on standard error and exit
code 2.
"""

__all__: list[str] = []
