#!/usr/bin/env bash
# Build the C runtime from native/ (CMake, shared library only) into
# $RBS_CS_CACHE/native-install (default integrations/code_saturne/.build),
# the prefix the case's Allrun compiles the solver against. The solver itself
# is compiled by Allrun (`code_saturne compile`: the case's user sources and
# stochastic_rebound/rbs_cs_rebound.c, linked with -lrebound_scatter).
#
#   integrations/code_saturne/build.sh
#
# Run install-deps.sh first. Prints its wall time.
#
# Copyright (C) 2026 the rebound-scatter authors. License: GPL-2.0-or-later
# (see LICENSE in this folder).
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/../.." && pwd)
cache=${RBS_CS_CACHE:-$here/.build}
prefix="$cache/native-install"

command -v code_saturne >/dev/null || {
    echo "code_saturne is not installed: run integrations/code_saturne/install-deps.sh first" >&2; exit 1; }
[ -f "$repo/native/CMakeLists.txt" ] || {
    echo "native/CMakeLists.txt not found: the C runtime is needed" >&2; exit 1; }

now_us() { local t=${EPOCHREALTIME/./}; echo "${t#0}"; }
t0=$(now_us)
echo "== C runtime (native/, CMake)"
cmake -S "$repo/native" -B "$cache/native-build" \
    -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_INSTALL_PREFIX="$prefix" \
    -DCMAKE_INSTALL_LIBDIR=lib \
    -DRBS_BUILD_STATIC=OFF >/dev/null
cmake --build "$cache/native-build" -j "${RBS_BUILD_JOBS:-2}" >/dev/null
cmake --install "$cache/native-build" >/dev/null
dt=$(( $(now_us) - t0 ))
printf '== C runtime (native/, CMake): %d.%01d s\n' $((dt / 1000000)) $(((dt % 1000000) / 100000))
echo "built $prefix/lib/librebound_scatter.so"
