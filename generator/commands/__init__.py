"""One module per ``urbangen`` sub-command (see :mod:`generator.cli`)."""
