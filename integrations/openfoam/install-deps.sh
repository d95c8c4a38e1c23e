#!/usr/bin/env bash
# Install what the OpenFOAM adapter needs on Debian bookworm, as root:
#
#   1. Debian's OpenFOAM v1912 (openfoam, libopenfoam), Open MPI, a compiler,
#      CMake and HDF5 (for native/) and lbzip2;
#   2. the OpenFOAM v1912 source, from `apt-get source openfoam` (Debian ships
#      no OpenFOAM headers and no tutorials): its src/, wmake/, etc/, bin/
#      and the whole tutorials/ tree (with tutorials/resources, the geometry
#      some tutorials take) are unpacked into $RBS_OPENFOAM_CACHE/OpenFOAM-v1912;
#   3. the wmake tools (wmkdepend, lemon) and the lnInclude folders of the
#      libraries the adapter includes.
#
# Idempotent: a finished step is skipped (remove $RBS_OPENFOAM_CACHE to start
# over). RBS_OPENFOAM_CACHE defaults to integrations/openfoam/.build; the one
# used is recorded in integrations/openfoam/.cache-location, where
# openfoam-env.sh finds it in a new shell. Each step prints its wall time.
# Then build.sh builds native/ and the adapter.
#
# Copyright (C) 2026 the rebound-scatter authors. License: GPL-3.0-or-later
# (see LICENSE in this folder).
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
export RBS_OPENFOAM_CACHE="${RBS_OPENFOAM_CACHE:-$here/.build}"
mkdir -p "$RBS_OPENFOAM_CACHE"
RBS_OPENFOAM_CACHE=$(cd "$RBS_OPENFOAM_CACHE" && pwd)
echo "$RBS_OPENFOAM_CACHE" > "$here/.cache-location"
tree="$RBS_OPENFOAM_CACHE/OpenFOAM-v1912"
download="$RBS_OPENFOAM_CACHE/download"

step_name=""
step_t0=0
now_us() { local t=${EPOCHREALTIME/./}; echo "${t#0}"; }
step() { step_name=$1; step_t0=$(now_us); echo "== $step_name"; }
step_done() {
    local dt=$(( $(now_us) - step_t0 ))
    printf '== %s: %d.%01d s\n' "$step_name" $((dt / 1000000)) $(((dt % 1000000) / 100000))
}

as_root() {
    if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi
}

# ---------------------------------------------------------------- 1. packages
packages=(openfoam libopenfoam openmpi-bin g++ make cmake libhdf5-dev lbzip2 dpkg-dev)
step "Debian packages (${packages[*]})"
missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
    echo "installing: ${missing[*]}"
    as_root apt-get update -q
    as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
else
    echo "all installed"
fi
step_done

# ------------------------------------------------------ 2. the v1912 sources
step "OpenFOAM v1912 source (apt-get source openfoam)"
if [ -f "$tree/.unpacked" ]; then
    echo "already unpacked in $tree"
else
    mkdir -p "$download"
    if ! ls "$download"/openfoam_*.orig.tar.* >/dev/null 2>&1; then
        # apt-get source needs a deb-src line for bookworm
        if ! apt-get source --print-uris -q openfoam >/dev/null 2>&1; then
            echo "adding a deb-src line for bookworm"
            as_root tee /etc/apt/sources.list.d/rebound-scatter-deb-src.sources >/dev/null <<'EOF'
Types: deb-src
URIs: http://deb.debian.org/debian
Suites: bookworm
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
EOF
            as_root apt-get update -q
        fi
        # only the tarballs: the tree is unpacked below, in part
        (cd "$download" && apt-get source --download-only -q openfoam > apt-get-source.log 2>&1) || {
            cat "$download/apt-get-source.log" >&2; echo "apt-get source openfoam failed" >&2; exit 1; }
    fi
    orig=$(ls "$download"/openfoam_*.orig.tar.* | head -n 1)
    [ -f "$orig" ] || { echo "no OpenFOAM source tarball in $download" >&2; exit 1; }
    rm -rf "$tree" "$tree.tmp"
    mkdir -p "$tree.tmp"
    top=$(set +o pipefail; tar -I lbzip2 -tf "$orig" 2>/dev/null | head -n 1 | cut -d/ -f1)
    tar -I lbzip2 -xf "$orig" -C "$tree.tmp" --strip-components=1 --wildcards \
        "$top/src/*" "$top/wmake/*" "$top/etc/*" "$top/bin/*" "$top/META-INFO/*" "$top/COPYING" \
        "$top/tutorials/*"
    mv "$tree.tmp" "$tree"
    touch "$tree/.unpacked" "$tree/.tutorials-unpacked"
fi
step_done

# a tree unpacked before the whole tutorials tree was: the rest of it
step "OpenFOAM v1912 tutorials"
if [ -f "$tree/.tutorials-unpacked" ]; then
    echo "already unpacked in $tree/tutorials"
else
    orig=$(ls "$download"/openfoam_*.orig.tar.* | head -n 1)
    top=$(set +o pipefail; tar -I lbzip2 -tf "$orig" 2>/dev/null | head -n 1 | cut -d/ -f1)
    tar -I lbzip2 -xf "$orig" -C "$tree" --strip-components=1 --wildcards "$top/tutorials/*"
    touch "$tree/.tutorials-unpacked"
fi
step_done

# shellcheck source=openfoam-env.sh
. "$here/openfoam-env.sh"

# ------------------------------------------------------ 3. wmake and headers
step "wmake tools"
if [ -x "$WM_PROJECT_DIR/platforms/tools/$WM_ARCH$WM_COMPILER/wmkdepend" ]; then
    echo "already built"
else
    "$WM_DIR/src/Allmake" >/dev/null
fi
step_done

step "lnInclude folders"
lninclude_dirs=(
    OpenFOAM OSspecific/POSIX finiteVolume meshTools fileFormats surfMesh
    dynamicMesh dynamicFvMesh lagrangian/basic lagrangian/intermediate lagrangian/spray
    lagrangian/distributionModels
    transportModels/compressible thermophysicalModels/specie thermophysicalModels/basic
    thermophysicalModels/thermophysicalProperties thermophysicalModels/reactionThermo
    thermophysicalModels/SLGThermo thermophysicalModels/radiation
    regionModels/regionModel regionModels/surfaceFilmModels
)
# wmakeLnInclude links one file per process: two at a time on two cores
for d in "${lninclude_dirs[@]}"; do
    [ -f "$FOAM_SRC/$d/lnInclude/.done" ] || echo "$d"
done | xargs -r -P "$WM_NCOMPPROCS" -I{} sh -c \
    'cd "$FOAM_SRC/{}" && rm -rf lnInclude && wmakeLnInclude -s . 2>/dev/null && touch lnInclude/.done'
step_done

echo "OpenFOAM v1912 headers and wmake in $WM_PROJECT_DIR; libraries in $FOAM_LIBBIN"
