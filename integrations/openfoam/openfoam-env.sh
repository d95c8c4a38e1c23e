# Environment for building the stochasticRebound adapter against Debian's
# OpenFOAM v1912 and for running its case and the stock tutorials with it.
# Source it from bash, in any shell:
#
#     . integrations/openfoam/openfoam-env.sh
#
# Building needs the outputs of install-deps.sh (the v1912 source tree with
# its wmake tools); running needs Debian's packages and the adapter build.sh
# built. Both scripts record the folder they used (RBS_OPENFOAM_CACHE, default
# integrations/openfoam/.build) in integrations/openfoam/.cache-location, so a
# new shell finds it without RBS_OPENFOAM_CACHE. Nothing here sources
# OpenFOAM's own etc/bashrc: Debian installs the libraries in /usr/lib and the
# solvers in /usr/bin, which that file does not know about.
#
# Copyright (C) 2026 the rebound-scatter authors. License: GPL-3.0-or-later
# (see LICENSE in this folder).

_rbs_of_here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
# the folder install-deps.sh and build.sh used: given, else the one they
# recorded, else the default
if [ -z "${RBS_OPENFOAM_CACHE:-}" ] && [ -f "$_rbs_of_here/.cache-location" ]; then
    RBS_OPENFOAM_CACHE=$(cat "$_rbs_of_here/.cache-location")
fi
export RBS_OPENFOAM_CACHE="${RBS_OPENFOAM_CACHE:-$_rbs_of_here/.build}"
_rbs_tree="$RBS_OPENFOAM_CACHE/OpenFOAM-v1912"

# wmake's view of the platform: the settings Debian's package was built with
# (debian/rules of the openfoam source package: Gcc, 64-bit, DP, 32-bit labels)
export WM_PROJECT=OpenFOAM
export WM_PROJECT_VERSION=v1912
# the unpacked v1912 tree (headers, wmake, etc/, bin/tools/RunFunctions, the
# tutorials); without it, Debian's etc/ is all a solver needs
if [ -f "$_rbs_tree/etc/controlDict" ]; then
    export WM_PROJECT_DIR="$_rbs_tree"
else
    export WM_PROJECT_DIR=/usr/share/openfoam
fi
export WM_DIR="$_rbs_tree/wmake"
export WM_ARCH=linux64
export WM_COMPILER=Gcc
export WM_COMPILER_TYPE=system
export WM_COMPILER_LIB_ARCH=64
export WM_COMPILE_OPTION=Opt
export WM_PRECISION_OPTION=DP
export WM_LABEL_SIZE=32
export WM_LABEL_OPTION=Int32
export WM_OSTYPE=POSIX
export WM_MPLIB=SYSTEMOPENMPI
export WM_OPTIONS=linux64GccDPInt32Opt
export WM_NCOMPPROCS="${WM_NCOMPPROCS:-2}"
export FOAM_API=1912
export FOAM_SRC="$_rbs_tree/src"
export FOAM_ETC="$WM_PROJECT_DIR/etc"
# the stock tutorials, with their geometry (tutorials/resources)
if [ -d "$_rbs_tree/tutorials/resources" ]; then
    export FOAM_TUTORIALS="$_rbs_tree/tutorials"
fi
# Debian's libOpenFOAM.so and friends
if [ -z "${FOAM_LIBBIN:-}" ]; then
    for _d in /usr/lib /usr/lib/openfoam/openfoam1912/lib /usr/lib/x86_64-linux-gnu; do
        if [ -e "$_d/liblagrangianIntermediate.so" ]; then FOAM_LIBBIN=$_d; break; fi
    done
    export FOAM_LIBBIN="${FOAM_LIBBIN:-/usr/lib}"
fi
# the adapter's library and the C runtime built from native/ (build.sh)
export FOAM_USER_LIBBIN="$RBS_OPENFOAM_CACHE/lib"
export RBS_NATIVE_PREFIX="${RBS_NATIVE_PREFIX:-$RBS_OPENFOAM_CACHE/native-install}"

case ":$PATH:" in
    *":$WM_DIR:"*) ;;
    *) export PATH="$WM_DIR:$PATH" ;;
esac
for _d in "$RBS_NATIVE_PREFIX/lib" "$FOAM_USER_LIBBIN"; do
    case ":${LD_LIBRARY_PATH:-}:" in
        *":$_d:"*) ;;
        *) export LD_LIBRARY_PATH="$_d${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" ;;
    esac
done
unset _d _rbs_of_here _rbs_tree
