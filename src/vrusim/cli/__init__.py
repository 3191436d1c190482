"""The `vrusim` command: one module per command, shared options in `options.py`."""
