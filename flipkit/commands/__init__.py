"""Sub-commands of the ``flipkit`` command line, one module each."""
