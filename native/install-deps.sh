#!/usr/bin/env bash
# Install what the native runtime (native/) needs to build and be tested: a C compiler, a C++ compiler
# (the tests compile a C++ example), CMake, HDF5's C development files, gfortran (the Fortran module),
# pkg-config. Idempotent: installs only what is missing.
#
#   native/install-deps.sh           install what is missing (apt-get as root on Debian/Ubuntu), else
#                                    print what to install
#   native/install-deps.sh --check   only check; exit 1 if something is missing
set -euo pipefail

check_only=0
if [[ "${1:-}" == "--check" ]]; then check_only=1; fi

missing_packages=()
missing_tools=()
have() { command -v "$1" >/dev/null 2>&1; }
hdf5_headers() {
    for dir in /usr/include/hdf5/serial /usr/include /usr/local/include /opt/homebrew/include; do
        [[ -f "$dir/hdf5.h" ]] && return 0
    done
    have h5cc && return 0
    return 1
}

have cc || have gcc || { missing_tools+=("C compiler"); missing_packages+=(gcc); }
have c++ || have g++ || { missing_tools+=("C++ compiler"); missing_packages+=(g++); }
have cmake || { missing_tools+=(cmake); missing_packages+=(cmake); }
have gfortran || { missing_tools+=(gfortran); missing_packages+=(gfortran); }
have pkg-config || { missing_tools+=(pkg-config); missing_packages+=(pkg-config); }
hdf5_headers || { missing_tools+=("HDF5 C development files"); missing_packages+=(libhdf5-dev); }

if [[ ${#missing_packages[@]} -eq 0 ]]; then
    echo "native/install-deps.sh: all present (C and C++ compilers, cmake, gfortran, pkg-config, HDF5 headers)"
    exit 0
fi
if [[ $check_only -eq 1 ]]; then
    echo "native/install-deps.sh: missing: ${missing_tools[*]}"
    exit 1
fi
if [[ $(id -u) -eq 0 ]] && have apt-get; then
    echo "native/install-deps.sh: installing ${missing_packages[*]}"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${missing_packages[@]}"
    exit 0
fi
echo "native/install-deps.sh: missing: ${missing_tools[*]}"
if have apt-get; then
    echo "  install them with:  sudo apt-get install ${missing_packages[*]}"
else
    echo "  Debian/Ubuntu packages: ${missing_packages[*]}"
    echo "  Fedora/RHEL:  sudo dnf install gcc gcc-c++ cmake gcc-gfortran pkgconf hdf5-devel"
    echo "  macOS (Homebrew):  brew install cmake gcc hdf5 pkg-config"
    echo "  conda:  conda install -c conda-forge c-compiler cxx-compiler fortran-compiler cmake hdf5 pkg-config"
fi
exit 1
