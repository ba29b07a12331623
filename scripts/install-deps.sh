#!/usr/bin/env bash
# Installs the Debian packages proxgen builds and tests with. Idempotent.
set -euo pipefail
packages=(
  build-essential cmake ninja-build ccache pkg-config python3
  libeigen3-dev liburdfdom-dev liburdfdom-tools libtinyxml2-dev libfmt-dev libyaml-cpp-dev
  nlohmann-json3-dev libcli11-dev libgtest-dev libgmock-dev libbenchmark-dev
  valgrind gnuplot-nox binutils libmujoco-dev
  gcc-arm-none-eabi libnewlib-arm-none-eabi libstdc++-arm-none-eabi-newlib qemu-system-arm
  clang libclang-rt-14-dev lld
  python3-dev pybind11-dev python3-pybind11 python3-numpy python3-pytest python3-matplotlib python3-yaml
  locales
)
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  $SUDO apt-get update
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y "${missing[@]}"
fi
echo "install-deps: all ${#packages[@]} packages present"
