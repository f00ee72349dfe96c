#!/usr/bin/env bash
# Sets FeelFlow up on a fresh Debian/Ubuntu machine that has python3:
#  1. the system packages in installer/system-packages.txt (apt, when root or through sudo),
#  2. a virtual environment in .venv with FeelFlow and its test dependencies.
# Safe to run again: it skips what is already there.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$here"

pkgs=$(grep -vE '^\s*(#|$)' installer/system-packages.txt | tr '\n' ' ')
missing=""
for p in $pkgs; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  if command -v apt-get >/dev/null 2>&1; then
    if [ "$(id -u)" = 0 ]; then sudo=""; elif command -v sudo >/dev/null 2>&1; then sudo="sudo"; else sudo="none"; fi
    if [ "$sudo" = none ]; then
      echo "setup: missing system packages:$missing (run as root or install sudo)" >&2
    else
      echo "setup: installing system packages:$missing"
      $sudo env DEBIAN_FRONTEND=noninteractive apt-get update -qq
      $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $missing >/dev/null
    fi
  else
    echo "setup: not a Debian/Ubuntu system; install the equivalents of:$missing" >&2
  fi
fi

if ! .venv/bin/python -m pip --version >/dev/null 2>&1; then
  rm -rf .venv   # none yet, or a half-made one (python3-venv was missing): make it afresh
  python3 -m venv .venv
fi
stamp=.venv/.feelflow-installed
if [ ! -f "$stamp" ] || [ pyproject.toml -nt "$stamp" ]; then
  .venv/bin/python -m pip install -q --upgrade pip
  .venv/bin/python -m pip install -q -e ".[test]"
  touch "$stamp"
fi
