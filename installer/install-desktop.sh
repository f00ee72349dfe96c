#!/usr/bin/env bash
# Puts FeelFlow into the desktop: an application-menu entry with its icon, `feelflow` on the
# PATH, and `.ffsession` files (docs/reference/session-format.md) that open in FeelFlow's replay when
# double-clicked. Usage:
#   installer/install-desktop.sh [--prefix DIR] [--bundle DIR] [--no-setup]   install (again: safe)
#   installer/install-desktop.sh [--prefix DIR] --uninstall    remove what install wrote
#   installer/install-desktop.sh --udev [--uninstall]          (as root) the device permission rule
# Per user by default (XDG): ${XDG_DATA_HOME:-~/.local/share}/{applications,icons,mime} and
# ~/.local/bin/feelflow. With --prefix DIR (for example /usr/local, as root): DIR/share and
# DIR/bin, for every user of the machine. From a checkout the launcher execs its .venv/bin/feelflow,
# made first by installer/setup.sh (skipped with --no-setup); from a bundle (this script inside
# the bundle folder, or --bundle DIR naming one) it execs the bundle's feelflow where it lies.
# Every file written is listed in a manifest (DATA/feelflow/installed-files.txt) with its checksum;
# --uninstall removes exactly those that still hold what was written, and the folders install
# created if they are empty (a bundle folder stays: delete it yourself).
# --udev writes /etc/udev/rules.d/70-feelflow.rules (python -m feelflow.haptics.udev):
# HID and serial haptic devices for the logged-in user; --udev --uninstall removes it.
# update-desktop-database, update-mime-database and gtk-update-icon-cache run when present.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"   # the checkout, or the bundle folder
assets="$here/installer"
me="install-desktop"

die() { echo "$me: $1" >&2; exit "${2:-1}"; }

prefix="" uninstall=0 setup=1 bundle="" udev=0
while [ $# -gt 0 ]; do
  case "$1" in
    --prefix) [ $# -ge 2 ] && [ -n "$2" ] || die "--prefix needs a folder (try --help)" 2; prefix="$2"; shift 2 ;;
    --prefix=*) prefix="${1#--prefix=}"; [ -n "$prefix" ] || die "--prefix needs a folder (try --help)" 2; shift ;;
    --uninstall) uninstall=1; shift ;;
    --no-setup) setup=0; shift ;;
    --bundle) [ $# -ge 2 ] && [ -n "$2" ] || die "--bundle needs the bundle folder (try --help)" 2; bundle="$2"; shift 2 ;;
    --bundle=*) bundle="${1#--bundle=}"; [ -n "$bundle" ] || die "--bundle needs the bundle folder (try --help)" 2; shift ;;
    --udev) udev=1; shift ;;
    -h|--help) sed -n '2,21p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) die "unknown option '$1' (usage: install-desktop.sh [--prefix DIR] [--bundle DIR] [--uninstall] [--no-setup] [--udev])" 2 ;;
  esac
done

# what the launcher runs: a bundle's program (--bundle DIR, or this script inside a bundle folder,
# which has `feelflow` beside installer/), else the checkout's venv
if [ -n "$bundle" ]; then
  [ -d "$bundle" ] || die "--bundle $bundle: no such folder" 2
  here_bundle="$(cd "$bundle" && pwd)"
elif [ -f "$here/feelflow" ] && [ -x "$here/feelflow" ] && [ ! -f "$here/pyproject.toml" ]; then
  here_bundle="$here"
else
  here_bundle=""
fi
if [ -n "$here_bundle" ]; then
  target="$here_bundle/feelflow"
  [ -f "$target" ] && [ -x "$target" ] || die "$target is missing: --bundle needs the folder installer/build-bundle.sh made (dist/feelflow)" 2
  python_m=("$target")
  setup=0
else
  target="$here/.venv/bin/feelflow"
  python_m=("$here/.venv/bin/python")
fi

# --- the udev rule (root) -----------------------------------------------------------------------
if [ "$udev" = 1 ]; then
  rules_dir="${FEELFLOW_UDEV_DIR:-/etc/udev/rules.d}"
  rules="$rules_dir/70-feelflow.rules"
  reload_udev() {
    if [ "$rules_dir" = /etc/udev/rules.d ] && command -v udevadm >/dev/null 2>&1; then
      udevadm control --reload-rules && udevadm trigger --subsystem-match=hidraw --subsystem-match=tty \
        || echo "$me: warning: udevadm could not reload the rules (unplug and replug the device)" >&2
    fi
  }
  [ -x "${python_m[0]}" ] || die "${python_m[0]} is missing: run installer/setup.sh first (or use a bundle)"
  text="$("${python_m[@]}" -m feelflow.haptics.udev)" || die "could not write the udev rule (see above)"
  if [ "$uninstall" = 1 ]; then
    if [ ! -e "$rules" ]; then echo "$me: no udev rule to remove ($rules)"; exit 0; fi
    if [ "$(cat "$rules")" = "$text" ]; then
      rm -f "$rules" || die "cannot remove $rules (run it with sudo)"
      reload_udev
      echo "$me: removed $rules"
    else
      echo "$me: kept $rules (changed since it was installed)" >&2
    fi
    exit 0
  fi
  [ -d "$rules_dir" ] && [ -w "$rules_dir" ] || die "cannot write into $rules_dir: the udev rule is for the whole machine (run it with sudo)"
  tmp="$(mktemp "$rules_dir/.feelflow-install.XXXXXX")" || die "cannot write into $rules_dir"
  printf '%s\n' "$text" > "$tmp" && chmod 644 "$tmp" && mv -f "$tmp" "$rules" || { rm -f "$tmp"; die "cannot write $rules"; }
  reload_udev
  echo "$me: udev rule installed: $rules (unplug and replug the device; serial ports also need the dialout group: sudo usermod -aG dialout \$USER)"
  exit 0
fi

if [ -n "$prefix" ]; then
  case "$prefix" in /*) ;; *) prefix="$(pwd)/$prefix" ;; esac
  data="$prefix/share" bin="$prefix/bin"
else
  [ -n "${HOME:-}" ] || die "HOME is not set: cannot find the per-user folders (or give --prefix DIR)"
  data="${XDG_DATA_HOME:-}"
  case "$data" in /*) ;; *) data="$HOME/.local/share" ;; esac   # the XDG spec ignores a relative one
  bin="$HOME/.local/bin"
fi
apps="$data/applications" icons="$data/icons/hicolor" mime="$data/mime"
manifest_dir="$data/feelflow" manifest="$data/feelflow/installed-files.txt"
for p in "$data" "$bin" "$here" "$target"; do
  case "$p" in *[\\\"\`\$%\']*|*$'\n'*|*$'\t'*)
    die "cannot install from or into a path with \\ \" \` \$ % ' or a tab/newline in it: $p" ;; esac
done

refresh_databases() {
  if command -v update-desktop-database >/dev/null 2>&1 && [ -d "$apps" ]; then
    update-desktop-database -q "$apps" || echo "$me: warning: update-desktop-database failed on $apps" >&2
  fi
  if command -v update-mime-database >/dev/null 2>&1 && [ -d "$mime/packages" ]; then
    update-mime-database "$mime" >/dev/null 2>&1 || echo "$me: warning: update-mime-database failed on $mime" >&2
  fi
  # an icon cache is optional; where one is kept, a stale one would hide the icon
  if command -v gtk-update-icon-cache >/dev/null 2>&1 && [ -f "$icons/icon-theme.cache" ]; then
    gtk-update-icon-cache -q -f "$icons" || echo "$me: warning: gtk-update-icon-cache failed on $icons" >&2
  fi
}

checksum() { sha256sum "$1" | cut -d' ' -f1; }

# --- uninstall ---------------------------------------------------------------------------------
if [ "$uninstall" = 1 ]; then
  [ -f "$manifest" ] || { echo "$me: nothing to uninstall (no $manifest)"; exit 0; }
  while IFS=$'\t' read -r kind sum path; do
    [ "$kind" = file ] || continue
    if [ -f "$path" ] && [ ! -L "$path" ]; then
      if [ "$(checksum "$path")" = "$sum" ]; then rm -f "$path"
      else echo "$me: kept $path (changed since it was installed)" >&2; fi
    fi
  done < "$manifest"
  dirs="$(grep "^dir"$'\t' "$manifest" | cut -f3 | sort -r || true)"
  rm -f "$manifest"
  # the databases the tools generated from our files alone go with them: a mime folder this
  # install created whose packages/ is now empty, a desktop cache alone in our applications/
  if grep -qxF "$mime" <<< "$dirs" && [ -z "$(ls -A "$mime/packages" 2>/dev/null)" ]; then
    rm -rf "$mime"
  fi
  if grep -qxF "$apps" <<< "$dirs" && [ -z "$(ls -A "$apps" 2>/dev/null | grep -vx mimeinfo.cache)" ]; then
    rm -f "$apps/mimeinfo.cache"
  fi
  refresh_databases
  # then the folders install created, deepest first, each only if nothing else is in it now
  rmdir "$manifest_dir" 2>/dev/null || true
  while IFS= read -r d; do [ -z "$d" ] || rmdir "$d" 2>/dev/null || true; done <<< "$dirs"
  echo "$me: FeelFlow removed from the desktop"
  exit 0
fi

# --- install -----------------------------------------------------------------------------------
if [ "$setup" = 1 ]; then
  bash "$here/installer/setup.sh" || die "installer/setup.sh failed (see above)"
fi
[ -x "$target" ] || die "$target is missing: run installer/setup.sh first (or drop --no-setup)"

# the folders install creates (kept across re-installs, so that uninstall removes them)
new_dirs=""
make_dir() {   # mkdir -p, noting each folder it creates
  local d="$1" missing=()
  while [ ! -d "$d" ]; do missing=("$d" "${missing[@]}"); d="$(dirname "$d")"; done
  for d in "${missing[@]}"; do
    mkdir "$d" 2>/dev/null || die "cannot create the folder $d (no permission? system-wide needs root)"
    new_dirs+="dir"$'\t'"-"$'\t'"$d"$'\n'
  done
}

# what an earlier install wrote (it may be overwritten); anything else in the way is not ours
declare -A ours=()
if [ -f "$manifest" ]; then
  while IFS=$'\t' read -r kind sum path; do
    if [ "$kind" = file ]; then ours["$path"]="$sum"; else new_dirs+="$kind"$'\t'"$sum"$'\t'"$path"$'\n'; fi
  done < "$manifest"
fi

written=""
check_free() {   # check_free SOURCE_FILE DEST: DEST is absent, ours, or already holds SOURCE_FILE
  local src="$1" dest="$2"
  if [ -e "$dest" ] || [ -L "$dest" ]; then
    if [ -z "${ours[$dest]:-}" ] && ! cmp -s "$src" "$dest"; then
      die "$dest already exists and was not written by this installer: move it away first"
    fi
  fi
}
put() {   # put SOURCE_FILE DEST MODE: atomic write (temp file in DEST's folder, then mv)
  local src="$1" dest="$2" mode="$3" tmp
  make_dir "$(dirname "$dest")"
  check_free "$src" "$dest"
  tmp="$(mktemp "$(dirname "$dest")/.feelflow-install.XXXXXX")" || die "cannot write into $(dirname "$dest")"
  cat "$src" > "$tmp" && chmod "$mode" "$tmp" && mv -f "$tmp" "$dest" || { rm -f "$tmp"; die "cannot write $dest"; }
  written+="file"$'\t'"$(checksum "$dest")"$'\t'"$dest"$'\n'
}

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

launcher="$bin/feelflow"
q="'"
printf '#!/bin/sh\n# FeelFlow, installed by %s/install-desktop.sh (--uninstall removes it)\nexec %s "$@"\n' \
  "$assets" "$q$target$q" > "$work/launcher"
case "$launcher" in   # the Desktop Entry spec's reserved characters (those not refused above) need quotes
  *[\ \>\<\~\|\&\;\*\?\#\(\)]*) launcher_exec="\"$launcher\"" ;;
  *) launcher_exec="$launcher" ;;
esac
entry="$(cat "$assets/feelflow.desktop.in")"
entry="${entry//@LAUNCHER_EXEC@/$launcher_exec}"
printf '%s\n' "${entry//@LAUNCHER@/$launcher}" > "$work/feelflow.desktop"

# refuse before writing anything, so that a conflict leaves no file behind
for pair in "$work/launcher|$launcher" "$assets/feelflow.svg|$icons/scalable/apps/feelflow.svg" \
            "$assets/feelflow-mime.xml|$mime/packages/feelflow.xml" "$work/feelflow.desktop|$apps/feelflow.desktop"; do
  check_free "${pair%%|*}" "${pair#*|}"
done
put "$work/launcher" "$launcher" 755
put "$assets/feelflow.svg" "$icons/scalable/apps/feelflow.svg" 644
put "$assets/feelflow-mime.xml" "$mime/packages/feelflow.xml" 644
put "$work/feelflow.desktop" "$apps/feelflow.desktop" 644

make_dir "$manifest_dir"
{ printf '%s' "$new_dirs" | sort -u; printf '%s' "$written"; } > "$work/manifest"
tmp="$(mktemp "$manifest_dir/.feelflow-install.XXXXXX")" || die "cannot write into $manifest_dir"
cat "$work/manifest" > "$tmp" && chmod 644 "$tmp" && mv -f "$tmp" "$manifest" || { rm -f "$tmp"; die "cannot write $manifest"; }

refresh_databases
echo "$me: FeelFlow installed: menu entry $apps/feelflow.desktop, command $launcher"
case ":${PATH:-}:" in *":$bin:"*) ;; *) echo "$me: note: $bin is not on your PATH yet (log out and in again, or add it)" ;; esac
