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
  zlib1g-dev                          # compressed binary VTK output
  python3-vtk9                        # scripts/render_frames.py (offscreen under Xvfb, below), the output read back by VTK (tests)
  python3-jsonschema                  # the scene files checked against their schema (tests)
  pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib  # the Python module, its tests, its plot example
  gnuplot-nox                         # plots in the reports
  doxygen                             # API reference (cmake --build build --target docs; optional)
  libglfw3-dev libgl-dev libimgui-dev libgl1-mesa-dri  # sinew view (docs/viewer.md)
  xvfb xauth                          # headless tests: sinew view and render_frames.py (xvfb-run)
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
