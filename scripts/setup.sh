#!/usr/bin/env bash
# Installs shadowlab's Debian 12 build and run dependencies (as root, or through sudo).
# Skips apt entirely when every package is already installed, so repeated runs are fast.
# Extra package names may be given (scripts/fuzz.sh asks for clang).
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config git
  libglm-dev nlohmann-json3-dev libtinygltf-dev libembree-dev libstb-dev libgtest-dev
  libosmesa6-dev libegl-dev libopengl-dev libgl-dev libglfw3-dev libimgui-dev
  assimp-testmodels python3 python3-matplotlib xvfb xauth fonts-dejavu-core
  # Sweeps on a Slurm cluster: tests/SweepSlurmTest.cpp runs a one-node cluster on this machine
  # (scripts/slurm_local.sh). slurm-wlm brings slurmctld, slurmd and the client (sbatch, squeue);
  # munge is its authentication daemon.
  slurm-wlm munge
  # tests/ReportTest.cpp opens report.html in headless chromium to check that its images decode.
  chromium
  # The portability matrix (scripts/portability.sh) runs the GL tests a second time on zink (GL on
  # Vulkan) over lavapipe: mesa-vulkan-drivers brings lavapipe and zink.
  mesa-vulkan-drivers
)

PACKAGES+=("$@")
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "setup: installing ${missing[*]}" >&2
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "setup: need root or sudo to install packages" >&2; exit 1; }
  SUDO="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
