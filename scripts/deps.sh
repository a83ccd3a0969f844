#!/usr/bin/env bash
# Installs the Debian 12 packages ictus needs, only those that are missing.
# Runs as root, or through sudo when not root. Usage: scripts/deps.sh [extra-package ...]
set -euo pipefail

packages=(
    build-essential cmake pkg-config ccache  # ccache: rebuilds of the same sources (scripts/build.sh)
    puredata-core puredata-dev pd-cyclone
    libode-dev libeigen3-dev liblo-dev liblo-tools nlohmann-json3-dev
    catch2
    clang libclang-rt-14-dev  # fuzz/ (libFuzzer: its runtime is only recommended by clang-14)
    python3 python3-venv python3-numpy python3-scipy python3-matplotlib python3-mido
    python3-markdown  # the references as HTML in the Pd library (scripts/doc_html.py)
    gem puredata-gui libgl1-mesa-dri xvfb xauth x11-utils imagemagick python3-pil  # Gem view, GUI (tests/ui)
    "$@"
)

missing=()
for p in "${packages[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
        missing+=("$p")
    fi
done

if [ ${#missing[@]} -eq 0 ]; then
    exit 0
fi

if [ "$(id -u)" -eq 0 ]; then
    sudo=()
elif command -v sudo >/dev/null; then
    sudo=(sudo)
else
    echo "deps.sh: need root or sudo to install: ${missing[*]}" >&2
    exit 1
fi

echo "deps.sh: installing ${missing[*]}"
"${sudo[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
