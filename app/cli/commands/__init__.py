"""Sub-commands of `feelflow`, one module each (see app/cli/main.py)."""
