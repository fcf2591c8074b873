#!/usr/bin/env bash
# Installs the Debian 12 packages sinew builds and tests with, skipping
# those already installed. Runs apt-get through sudo when not root.
set -euo pipefail

packages=(
  cmake g++ make pkg-config
  libtbb-dev libeigen3-dev            # CPU backend, linear algebra
  libgtest-dev libbenchmark-dev       # tests, benchmarks
  ocl-icd-opencl-dev opencl-headers pocl-opencl-icd            # OpenCL (PoCL: CPU device for tests)
  libvulkan-dev glslc mesa-vulkan-drivers vulkan-validationlayers  # Vulkan (lavapipe: CPU device)
  libopenvdb-dev libnanovdb-dev libboost-dev                   # level sets
  libembree-dev                       # CPU broad phase
  nlohmann-json3-dev libcli11-dev      # scene files, the sinew runner
  python3-jsonschema                  # the scene files checked against their schema (tests)
  gnuplot-nox                         # plots in the reports
  doxygen                             # API reference (cmake --build build --target docs; optional)
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages present"
  exit 0
fi

sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
echo "install_deps: installing ${missing[*]}"
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
