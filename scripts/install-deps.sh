#!/usr/bin/env bash
# Installs the Debian (bookworm) packages capstan builds and runs with. Idempotent.
set -euo pipefail
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
packages=(trilinos-all-dev libmumps-dev libptscotch-dev libscotch-dev libmetis-dev libhdf5-openmpi-dev
          openmpi-bin libopenblas0-serial libgtest-dev cmake g++ make python3 python3-numpy python3-matplotlib python3-h5py)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
echo "capstan dependencies installed"
