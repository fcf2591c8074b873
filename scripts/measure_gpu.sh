#!/usr/bin/env bash
# The GPU measurement suite: on the machine it runs on, from a folder made by
# scripts/pack_for_device.sh, run from the repository's root (the scenes and
# the packed meshes are read from there):
#   .gpu/measure_gpu.sh [RESULTS_DIR]     (default: $OUT, else ./gpu_results)
# In this order, each with a time limit so the whole suite ends within about
# nine minutes on a 16-core GPU machine:
#   1. the agreement tests of every backend-parameterised suite (numbers from
#      a backend that disagrees with cpu are worthless);
#   2. the cube (xpbd and Neo-Hookean), mesh-contact, contact-colouring and
#      dispatch benchmarks, the retraction and bleeding reference scenes, and the organ step on kidney_57k and liver_382k, on
#      opencl and vulkan (cpu alongside);
#   3. every scene file under scenes/ through the runner on opencl and vulkan:
#      its per-stage profile, what the host read back and waited for per
#      frame, and (Vulkan timestamps) its device time and costliest kernels;
#   4. every example on opencl and vulkan (its own frame lines).
# SINEW_GPU_PARTS picks parts (default "tests benchmarks scenes examples");
# SINEW_GPU_FRAMES caps the scenes' frames (default 60); SINEW_BENCH_FILTER
# limits the cube sizes (a Google Benchmark regex). With $OUT set (the device
# tool), the results come back as one archive, gpu_results.tar.gz, and the
# summary beside it.
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
repo=$(pwd)
results=${1:-${OUT:-./gpu_results}}
parts=${SINEW_GPU_PARTS:-tests benchmarks scenes examples}
frames=${SINEW_GPU_FRAMES:-60}
mkdir -p "$results"
summary="$results/summary.txt"
: > "$summary"
note() { echo "$*" | tee -a "$summary"; }
wants() { [[ " $parts " == *" $1 "* ]]; }

# The programs, unpacked once per machine (xz through tar, or Python where
# the machine has no xz).
work=/tmp/sinew_gpu
if [ ! -x "$work/bin/sinew" ]; then
  mkdir -p "$work"
  tar -C "$work" -xJf "$here/payload.tar.xz" 2>/dev/null ||
    python3 -c "import sys, tarfile; tarfile.open(sys.argv[1]).extractall(sys.argv[2])" "$here/payload.tar.xz" "$work" ||
    { note "measure_gpu: cannot unpack $here/payload.tar.xz"; exit 1; }
fi
bin=$work/bin
export LD_LIBRARY_PATH="$work/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"

# The data where the programs were built to look for it (their compiled-in
# SINEW_DATA_DIR, also the runner's "data:" folder): the repository's data/
# with the meshes unpacked, as the build's configure step does.
data_dir=$(cat "$here/data_dir.txt")
export SINEW_DATA_DIR=$data_dir
if [ ! -f "$data_dir/meshes/tet/liver_382k.node" ]; then
  mkdir -p "$data_dir" && cp -r "$repo/data/." "$data_dir/"
  find "$data_dir" -name '*.tar.xz' | while read -r archive; do
    dir=$(dirname "$archive")
    tar -C "$dir" -xJf "$archive" 2>/dev/null ||
      python3 -c "import sys, tarfile; tarfile.open(sys.argv[1]).extractall(sys.argv[2])" "$archive" "$dir"
    rm -f "$archive"
  done
fi

export SINEW_VULKAN_TIMESTAMPS=1 SINEW_VULKAN_VALIDATION=0
# NVIDIA containers may ship the drivers without registering them: point the
# Vulkan loader at the driver's ICD file, and ocl-icd at its OpenCL library.
nv_icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
[ -z "${VK_DRIVER_FILES:-}" ] && [ -f "$nv_icd" ] && export VK_DRIVER_FILES=$nv_icd
if [ ! -e /etc/OpenCL/vendors/nvidia.icd ] && [ -z "${OCL_ICD_VENDORS:-}" ]; then
  nv_cl=$(ldconfig -p 2>/dev/null | awk '/libnvidia-opencl.so.1/ {print $NF; exit}')
  if [ -n "$nv_cl" ]; then
    mkdir -p "$work/icd" && echo "$nv_cl" > "$work/icd/nvidia.icd" && export OCL_ICD_VENDORS="$work/icd"
  fi
fi
{
  echo "date: $(date -u)"
  nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv 2>/dev/null || echo "nvidia-smi: not found"
  ls /etc/OpenCL/vendors "${OCL_ICD_VENDORS:-/nonexistent}" 2>/dev/null | sed 's/^/OpenCL ICD: /'
  echo "VK_DRIVER_FILES=${VK_DRIVER_FILES:-}"
  echo "cores: $(nproc)"
} > "$results/machine.txt"
cat "$results/machine.txt" >> "$summary"

# runs NAME LIMIT_S COMMAND...: the command's output into NAME.txt, its exit
# status (124: it ran past the limit) into the summary.
runs() {
  local name=$1 limit=$2
  shift 2
  local start=$SECONDS
  timeout "$limit" "$@" > "$results/$name.txt" 2>&1
  note "$name: exit $? in $((SECONDS - start)) s"
}

if wants tests; then
  # Every suite parameterised by backend, and the backends' own tests.
  filter='Backends/*:GpuBackends/*:OpenclBackend*:VulkanBackend*:DeviceBvh*:SceneDeviceRange*'
  for t in test_backends test_xpbd test_collision test_fluid test_tissue test_topology test_robustness; do
    runs "tests_$t" 240 "$bin/$t" --gtest_filter="$filter" --gtest_brief=1
    grep -E '^\[  (PASSED|FAILED|SKIPPED) ' "$results/tests_$t.txt" | sed "s/^/  $t: /" >> "$summary"
  done
fi

if wants benchmarks; then
  for backend in opencl vulkan; do
    for material in xpbd neo_hookean; do
      SINEW_BACKEND=$backend SINEW_MATERIAL=$material runs "cube_${material}_${backend}" 120 \
        "$bin/bench_cube" --benchmark_filter="${SINEW_BENCH_FILTER:-.}" --benchmark_repetitions=3 \
        --benchmark_report_aggregates_only=true --benchmark_out="$results/cube_${material}_${backend}.csv" \
        --benchmark_out_format=csv
    done
  done
  for backend in opencl vulkan; do
    SINEW_BACKEND=$backend runs "mesh_contacts_${backend}" 120 "$bin/bench_mesh_contacts" \
      --benchmark_out="$results/mesh_contacts_${backend}.csv" --benchmark_out_format=csv
  done
  runs dispatch 60 "$bin/bench_dispatch" --benchmark_out="$results/dispatch.csv" --benchmark_out_format=csv
  for backend in cpu opencl vulkan; do
    runs "retraction_${backend}" 90 "$bin/bench_retraction" "$backend" 60
    runs "bleeding_organ_${backend}" 90 "$bin/bleeding_organ" --backend "$backend" --frames 60
  done
  runs contact_coloring 120 "$bin/bench_contact_coloring" --benchmark_out="$results/contact_coloring.csv" \
    --benchmark_out_format=csv
  for mesh in kidney_57k liver_382k; do
    for backend in cpu opencl vulkan; do
      runs "organ_step_${mesh}_${backend}" 90 "$bin/organ_step" "$backend" "$data_dir/meshes/tet/$mesh.node" 30
      tail -1 "$results/organ_step_${mesh}_${backend}.txt" | sed 's/^/  /' >> "$summary"
    done
  done
fi

if wants scenes; then
  for scene in "$repo"/scenes/*.json; do
    name=$(basename "$scene" .json)
    for backend in opencl vulkan; do
      runs "scene_${name}_${backend}" 90 "$bin/sinew" run "$scene" --backend "$backend" --frames "$frames" --quiet
      grep -E '^(profile|host transfers|device time)' "$results/scene_${name}_${backend}.txt" | sed 's/^/  /' >> "$summary"
    done
  done
fi

if wants examples; then
  scratch=$(mktemp -d)
  for example in organ_contact retraction bleeding_kidney suturing cholecystectomy bleeding bone_burr haptic_drag; do
    for backend in opencl vulkan; do
      runs "example_${example}_${backend}" 90 "$bin/$example" --backend "$backend" --out "$scratch/$example"
    done
  done
  rm -rf "$scratch"
fi

# The device tool brings back at most 8 files: one archive of everything.
if [ -n "${OUT:-}" ] && [ "$results" = "$OUT" ]; then
  tar -C "$results" -czf /tmp/gpu_results.tar.gz --exclude=summary.txt . && mv /tmp/gpu_results.tar.gz "$results/"
  find "$results" -mindepth 1 -maxdepth 1 ! -name gpu_results.tar.gz ! -name summary.txt -exec rm -rf {} +
fi
