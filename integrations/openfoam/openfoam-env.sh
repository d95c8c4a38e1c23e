# Environment for building the stochasticRebound adapter against Debian's
# OpenFOAM v1912 and for running its case. Source it from bash:
#
#     . integrations/openfoam/openfoam-env.sh
#
# It needs the outputs of install-deps.sh (the v1912 source tree with its
# wmake tools, in $RBS_OPENFOAM_CACHE) for building; running the solvers only
# needs Debian's packages. Nothing here sources OpenFOAM's own etc/bashrc:
# Debian installs the libraries in /usr/lib and the solvers in /usr/bin, which
# that file does not know about.
#
# Copyright (C) 2026 the rebound-scatter authors. License: GPL-3.0-or-later
# (see LICENSE in this folder).

_rbs_of_here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
export RBS_OPENFOAM_CACHE="${RBS_OPENFOAM_CACHE:-$_rbs_of_here/.build}"

# wmake's view of the platform: the settings Debian's package was built with
# (debian/rules of the openfoam source package: Gcc, 64-bit, DP, 32-bit labels)
export WM_PROJECT=OpenFOAM
export WM_PROJECT_VERSION=v1912
export WM_PROJECT_DIR="$RBS_OPENFOAM_CACHE/OpenFOAM-v1912"
export WM_DIR="$WM_PROJECT_DIR/wmake"
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
export FOAM_SRC="$WM_PROJECT_DIR/src"
export FOAM_ETC="$WM_PROJECT_DIR/etc"
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
unset _d _rbs_of_here
