#!/usr/bin/env bash
# Sets everything up (installer/setup.sh), then runs the default test suite under a virtual
# X screen (GUI tests need a real window with OpenGL; see docs/testing.md).
# Extra arguments go to pytest, for example: installer/run-tests.sh -m slow
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$here"
bash installer/setup.sh
exec xvfb-run -a -s "-screen 0 1600x1000x24" .venv/bin/python -m pytest "$@"
