#!/usr/bin/env bash
# Measures the GPU backends on the machine it runs on, from a folder made by
# scripts/pack_for_device.sh (run from inside that folder's parent):
#   .gpu/measure_gpu.sh [RESULTS_DIR]     (default: $OUT, else ./gpu_results)
# Writes, per backend (opencl, vulkan) and material (xpbd, neo_hookean), the
# cube benchmark as CSV (with device_ms/solve_device_ms from Vulkan
# timestamps), the dispatch cost, the agreement tests' log, and the devices
# found. A backend without a device is reported and skipped.
# SINEW_BENCH_FILTER limits the cube sizes (a Google Benchmark regex).
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
results=${1:-${OUT:-./gpu_results}}
mkdir -p "$results"
export LD_LIBRARY_PATH="$here/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export SINEW_VULKAN_TIMESTAMPS=1
# NVIDIA containers may ship the drivers without registering them: point the
# Vulkan loader at the driver's ICD file, and ocl-icd at its OpenCL library.
nv_icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
[ -z "${VK_DRIVER_FILES:-}" ] && [ -f "$nv_icd" ] && export VK_DRIVER_FILES=$nv_icd
if [ ! -e /etc/OpenCL/vendors/nvidia.icd ] && [ -z "${OCL_ICD_VENDORS:-}" ]; then
  nv_cl=$(ldconfig -p 2>/dev/null | awk '/libnvidia-opencl.so.1/ {print $NF; exit}')
  if [ -n "$nv_cl" ]; then
    mkdir -p "$here/icd" && echo "$nv_cl" > "$here/icd/nvidia.icd" && export OCL_ICD_VENDORS="$here/icd"
  fi
fi
{
  echo "date: $(date -u)"
  nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv 2>/dev/null || echo "nvidia-smi: not found"
  ls /etc/OpenCL/vendors "${OCL_ICD_VENDORS:-/nonexistent}" 2>/dev/null | sed 's/^/OpenCL ICD: /'
  echo "VK_DRIVER_FILES=${VK_DRIVER_FILES:-}"
} > "$results/machine.txt"
# Agreement and backend tests first: numbers from a backend that disagrees with cpu are worthless.
SINEW_VULKAN_VALIDATION=0 "$here/bin/test_backends" > "$results/test_backends.log" 2>&1
echo "test_backends exit $? (log: test_backends.log)"
for backend in opencl vulkan; do
  for material in xpbd neo_hookean; do
    SINEW_BACKEND=$backend SINEW_MATERIAL=$material "$here/bin/bench_cube" --benchmark_filter="${SINEW_BENCH_FILTER:-.}" --benchmark_repetitions=3 \
      --benchmark_report_aggregates_only=true --benchmark_out="$results/cube_${material}_${backend}.csv" \
      --benchmark_out_format=csv > "$results/cube_${material}_${backend}.txt" 2>&1
    echo "bench_cube $backend $material exit $?"
  done
done
"$here/bin/bench_dispatch" --benchmark_out="$results/dispatch.csv" --benchmark_out_format=csv > "$results/dispatch.txt" 2>&1
echo "bench_dispatch exit $?"
