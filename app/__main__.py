"""`python -m feelflow.app` is the `feelflow` command."""
import sys

from feelflow.app.cli.main import main

sys.exit(main())
