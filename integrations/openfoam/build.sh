#!/usr/bin/env bash
# Build the C runtime from native/ (CMake, installed into
# $RBS_OPENFOAM_CACHE/native-install) and the stochasticRebound adapter
# (wmake, against the OpenFOAM v1912 headers install-deps.sh unpacked, linked
# with Debian's libraries) into $RBS_OPENFOAM_CACHE/lib/libstochasticRebound.so.
#
#   integrations/openfoam/build.sh            # both
#   RBS_NATIVE_PREFIX=/opt/rbs build.sh       # use an installed C runtime
#   RBS_OPENFOAM_CLOUDS="colliding MPPIC" build.sh   # these cloud families only
#
# The cloud families (one translation unit each, compiled in parallel):
# kinematic colliding MPPIC thermo reacting reactingMultiphase (with coal)
# heterogeneous spray; all by default.
#
# Run install-deps.sh first. Each step prints its wall time.
#
# Copyright (C) 2026 the rebound-scatter authors. License: GPL-3.0-or-later
# (see LICENSE in this folder).
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/../.." && pwd)
native_given=${RBS_NATIVE_PREFIX:-}
# shellcheck source=openfoam-env.sh
. "$here/openfoam-env.sh"
# where a new shell's openfoam-env.sh finds the library
mkdir -p "$RBS_OPENFOAM_CACHE"
(cd "$RBS_OPENFOAM_CACHE" && pwd) > "$here/.cache-location"

if [ ! -x "$WM_PROJECT_DIR/platforms/tools/$WM_ARCH$WM_COMPILER/wmkdepend" ]; then
    echo "No OpenFOAM v1912 headers and wmake tools in $WM_PROJECT_DIR:" \
         "run integrations/openfoam/install-deps.sh first" >&2
    exit 1
fi

now_us() { local t=${EPOCHREALTIME/./}; echo "${t#0}"; }
step() { step_name=$1; step_t0=$(now_us); echo "== $step_name"; }
step_done() {
    local dt=$(( $(now_us) - step_t0 ))
    printf '== %s: %d.%01d s\n' "$step_name" $((dt / 1000000)) $(((dt % 1000000) / 100000))
}

jobs=${WM_NCOMPPROCS:-2}

# ------------------------------------------------------------ the C runtime
if [ -z "$native_given" ]; then
    step "C runtime (native/, CMake)"
    [ -f "$repo/native/CMakeLists.txt" ] || {
        echo "native/CMakeLists.txt not found: the C runtime is needed" >&2; exit 1; }
    cmake -S "$repo/native" -B "$RBS_OPENFOAM_CACHE/native-build" \
        -DCMAKE_BUILD_TYPE=Release \
        -DCMAKE_INSTALL_PREFIX="$RBS_NATIVE_PREFIX" \
        -DCMAKE_INSTALL_LIBDIR=lib \
        -DRBS_BUILD_STATIC=OFF >/dev/null
    cmake --build "$RBS_OPENFOAM_CACHE/native-build" -j "$jobs" >/dev/null
    cmake --install "$RBS_OPENFOAM_CACHE/native-build" >/dev/null
    step_done
fi
[ -f "$RBS_NATIVE_PREFIX/include/rebound_scatter.h" ] || {
    echo "no rebound_scatter.h under $RBS_NATIVE_PREFIX/include" >&2; exit 1; }

# ------------------------------------------------------------- the adapter
step "stochasticRebound adapter (wmake libso)"
# built from a copy, so the source folder stays clean (wmake writes its
# objects next to Make/)
src="$RBS_OPENFOAM_CACHE/adapter/stochasticRebound"
mkdir -p "$src/Make" "$FOAM_USER_LIBBIN"
for f in "$src"/*.[CH]; do  # sources since removed
    if [ -e "$f" ] && [ ! -e "$here/stochasticRebound/${f##*/}" ]; then rm -f "$f"; fi
done
make_files=("$here"/stochasticRebound/Make/files)
[ -z "${RBS_OPENFOAM_CLOUDS:-}" ] || make_files=()
for f in "$here"/stochasticRebound/*.[CH] "${make_files[@]}" "$here"/stochasticRebound/Make/options; do
    rel=${f#"$here"/stochasticRebound/}
    cmp -s "$f" "$src/$rel" 2>/dev/null || cp "$f" "$src/$rel"
done
# the cloud families asked for: Make/files of the copy names only theirs
families=(kinematic colliding MPPIC thermo reacting reactingMultiphase heterogeneous spray)
if [ -n "${RBS_OPENFOAM_CLOUDS:-}" ]; then
    {
        echo "stochasticReboundCore.C"
        for family in $RBS_OPENFOAM_CLOUDS; do
            case " ${families[*]} " in
                *" $family "*) echo "makeStochasticRebound${family^}.C" ;;
                *) echo "RBS_OPENFOAM_CLOUDS: unknown cloud family $family; the families are ${families[*]}" >&2
                   exit 1 ;;
            esac
        done
        echo
        echo 'LIB = $(FOAM_USER_LIBBIN)/libstochasticRebound'
    } > "$src/Make/files.selected"
    cmp -s "$src/Make/files.selected" "$src/Make/files" || mv "$src/Make/files.selected" "$src/Make/files"
    rm -f "$src/Make/files.selected"
fi
(cd "$src" && wmake -s -j "$jobs" libso >"$RBS_OPENFOAM_CACHE/adapter/log.wmake" 2>&1) || {
    cat "$RBS_OPENFOAM_CACHE/adapter/log.wmake" >&2; exit 1; }
step_done
echo "built $FOAM_USER_LIBBIN/libstochasticRebound.so"
