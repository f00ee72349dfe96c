#!/usr/bin/env bash
# Sets everything up (installer/setup.sh), then starts FeelFlow on its default scene.
# Without a display it falls back to a headless run of the default scene.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$here"
bash installer/setup.sh
exec .venv/bin/feelflow "$@"
