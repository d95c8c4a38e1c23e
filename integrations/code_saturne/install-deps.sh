#!/usr/bin/env bash
# Install what the code_saturne integration needs on Debian bookworm, as root
# (or with sudo): Debian's code_saturne 6.0 with its headers (code-saturne,
# code-saturne-include), Open MPI, C and Fortran compilers (the case's user
# sources are compiled by `code_saturne compile`), CMake and HDF5 (for
# native/). Idempotent: installs only what is missing; prints its wall time.
# Then build.sh builds native/.
#
# Copyright (C) 2026 the rebound-scatter authors. License: GPL-2.0-or-later
# (see LICENSE in this folder).
set -euo pipefail

now_us() { local t=${EPOCHREALTIME/./}; echo "${t#0}"; }
t0=$(now_us)
as_root() {
    if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi
}

packages=(code-saturne code-saturne-include openmpi-bin gcc gfortran make cmake libhdf5-dev)
echo "== Debian packages (${packages[*]})"
if ! command -v dpkg-query >/dev/null || ! command -v apt-get >/dev/null; then
    echo "not a Debian system: install code_saturne 6.0 with its headers, Open MPI, C and Fortran" \
         "compilers, CMake and HDF5's development files, then run build.sh" >&2
    exit 1
fi
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
version=$(dpkg-query -W -f='${Version}' code-saturne)
case "$version" in
    6.0.*) ;;
    *) echo "code-saturne $version is installed; the integration is written for 6.0" >&2; exit 1 ;;
esac
dt=$(( $(now_us) - t0 ))
printf '== Debian packages: %d.%01d s (code-saturne %s)\n' $((dt / 1000000)) $(((dt % 1000000) / 100000)) "$version"
