"""`python -m app` is the `feelflow` command."""
import sys

from app.cli import main

sys.exit(main())
