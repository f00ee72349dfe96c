#!/usr/bin/env bash
# Builds the FeelFlow bundle: one folder that runs without Python (installer/feelflow.spec).
# Usage: installer/build-bundle.sh [WORK_DIR]
# WORK_DIR (default ${FEELFLOW_BUNDLE_WORK:-/tmp/bundle-build}) gets a build venv (venv/,
# made once with python3 and reused), a clean copy of this checkout (src/: git's tracked and
# untracked-but-not-ignored files), PyInstaller's work files (pyi/) and the bundle:
# WORK_DIR/dist/feelflow/feelflow. Each build replaces the previous one. Needs python3 (3.11+)
# with venv and network access to PyPI (or a pip cache) the first time.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
me="build-bundle"
die() { echo "$me: $1" >&2; exit "${2:-1}"; }
case "${1:-}" in -h|--help) sed -n '2,8p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;; esac
work="${1:-${FEELFLOW_BUNDLE_WORK:-/tmp/bundle-build}}"
case "$work" in /*) ;; *) work="$(pwd)/$work" ;; esac
case "$work/" in "$here"/*) die "build outside the checkout (a bundle is several hundred MB): $work" 2 ;; esac
python="${PYTHON:-python3}"
mkdir -p "$work" || die "cannot create $work"

if [ ! -x "$work/venv/bin/python" ]; then
  "$python" -m venv "$work/venv" || die "$python -m venv failed (Debian: apt install python3-venv)"
fi
py="$work/venv/bin/python"

echo "$me: copying the checkout to $work/src"
rm -rf "$work/src"
mkdir -p "$work/src"
if git -C "$here" rev-parse --git-dir >/dev/null 2>&1; then
  (cd "$here" && git ls-files -z --cached --others --exclude-standard \
     | while IFS= read -r -d '' f; do [ -e "$f" ] && printf '%s\0' "$f"; done \
     | tar --null -T - -cf -) | tar -xf - -C "$work/src"
else
  tar -C "$here" --exclude=./.venv --exclude=./build --exclude=./dist -cf - . | tar -xf - -C "$work/src"
fi

echo "$me: installing FeelFlow and PyInstaller into $work/venv"
"$py" -m pip install -q --disable-pip-version-check "$work/src[bundle]" || die "pip install failed (see above)"
"$py" -m pip install -q --disable-pip-version-check --force-reinstall --no-deps "$work/src" \
  || die "pip install of the checkout failed (see above)"

echo "$me: running PyInstaller"
rm -rf "$work/dist" "$work/pyi"
(cd "$work" && "$py" -m PyInstaller --noconfirm --clean --log-level WARN \
   --distpath "$work/dist" --workpath "$work/pyi" "$work/src/installer/feelflow.spec") \
  || die "PyInstaller failed (see above)"
rm -rf "$work/src/build"
exe="$work/dist/feelflow/feelflow"
[ -x "$exe" ] || [ -x "$exe.exe" ] || die "PyInstaller finished but $exe is missing"
echo "$me: built $exe ($(du -sh "$work/dist/feelflow" | cut -f1))"
