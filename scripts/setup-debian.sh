#!/usr/bin/env bash
# Installs every FrostMPM build/test dependency from Debian 12 packages. Idempotent.
set -euo pipefail
PKGS=(
  build-essential cmake ninja-build ccache pkg-config git
  libeigen3-dev libyaml-cpp-dev libboost-dev libboost-filesystem-dev libboost-system-dev
  trilinos-all-dev libptscotch-dev libhdf5-openmpi-dev libopenmpi-dev openmpi-bin
  catch2 libcli11-dev libspdlog-dev libfmt-dev libmuparser-dev libudunits2-dev
  nlohmann-json3-dev python3-numpy python3-scipy python3-matplotlib python3-h5py
)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#PKGS[@]} packages present"
  exit 0
fi
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
echo "setup: installed ${#missing[@]} packages"
