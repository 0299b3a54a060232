#!/usr/bin/env bash
# Installs the Debian packages Cairn needs that are missing. Safe to run again: it installs nothing when all
# are present. Needs root (or passwordless sudo) only when something is missing.
set -euo pipefail

packages=(
    cmake ninja-build g++ pkg-config
    clang libclang-rt-14-dev  # the ASan+UBSan build and its libFuzzer harnesses
    libeigen3-dev         # all math
    librecast-dev         # Recast/Detour navmesh
    libtinyobjloader-dev  # OBJ level meshes
    libtinygltf-dev       # glTF level meshes
    libcli11-dev          # the demo's and tools' command-line flags
    nlohmann-json3-dev    # the baker's JSON summary
    libgtest-dev libgmock-dev
    libbenchmark-dev      # benchmarks
    librapidcheck-dev     # property tests
)

missing=()
for package in "${packages[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
        missing+=("$package")
    fi
done

if [ ${#missing[@]} -eq 0 ]; then
    exit 0
fi

echo "cairn setup: installing missing packages: ${missing[*]}"
if [ "$(id -u)" -eq 0 ]; then
    as_root=()
elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
    as_root=(sudo -n)
else
    echo "cairn setup: these Debian packages are missing and I am not root: ${missing[*]}" >&2
    echo "cairn setup: run: sudo apt-get install -y ${missing[*]}" >&2
    exit 1
fi
export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update -qq
"${as_root[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
