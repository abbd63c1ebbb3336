#!/usr/bin/env bash
# Debian packages that `cargo bench -p subtess --features opensubdiv --bench opensubdiv`
# needs: the `opensubdiv` feature pulls in opensubdiv-petite, whose -sys crate builds OpenSubdiv
# 3.7 from C++ source with cmake and generates its bindings with bindgen (libclang).
# The default build, the tests and CI need none of this.
#
# Usage: scripts/install-opensubdiv-deps.sh   (as root, or with sudo available)
set -euo pipefail

packages=(cmake libclang-dev g++)

missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
    echo "already installed: ${packages[*]}"
    exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then
    sudo="sudo"
fi
$sudo apt-get update
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y "${missing[@]}"
echo "installed: ${missing[*]}"
echo "keep the C++ build gentle on a small machine:"
echo "  CMAKE_BUILD_PARALLEL_LEVEL=2 CARGO_BUILD_JOBS=2 cargo bench -p subtess --features opensubdiv --bench opensubdiv"
